// SPDX-License-Identifier: Apache-2.0
#include "fusedet/experiments/cnn_peer.h"

#include <chrono>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "fusedet/core/cpu_time.h"

namespace fusedet::boosting {

CnnPeerRun runCnnPeer(fusion::Network& network, const std::vector<PeerFrame>& frames,
                      const std::vector<std::string>& classes,
                      const std::function<MatchConfig(const std::string&)>& matchFor,
                      const fusion::CocoDetectionRule& rule, const std::function<void(std::size_t)>& progress) {
  using Clock = std::chrono::steady_clock;
  CnnPeerRun run;
  run.network = network.identity();
  std::map<std::string, MatchConfig> match;
  for (const std::string& c : classes) match[c] = matchFor(c);
  run.rules = match;
  double ms = 0, cpuMs = 0;
  for (std::size_t i = 0; i < frames.size(); ++i) {
    const cv::Mat bgr = cv::imread(frames[i].image.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) throw std::runtime_error(frames[i].image.string() + ": cannot read the image");
    const auto t0 = Clock::now();
    const double cpu0 = processCpuMs();
    const std::vector<Detection> dets = fusion::cocoDetections(network.run(bgr), rule);
    cpuMs += processCpuMs() - cpu0;
    ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    for (const std::string& c : classes) {
      // matchDetections considers only detections of the evaluated class.
      const StackMatch m = matchDetections(dets, frames[i].labels, match[c]);
      run.frames[c].push_back(frameOutcome(dets, m));
      run.counts[c].add(m);
    }
    if (progress) progress(i);
  }
  const double n = frames.empty() ? 1.0 : static_cast<double>(frames.size());
  run.msPerFrame = ms / n;
  run.cpuMsPerFrame = cpuMs / n;
  return run;
}

RunOutcomes cnnPeerOutcomes(const CnnPeerRun& run, const std::vector<PeerFrame>& frames, const std::string& config,
                            const std::string& command) {
  RunOutcomes out;
  out.command = command;
  for (const auto& [cls, outcomes] : run.frames) {
    OutcomeSet set;
    set.className = cls;
    set.protocol = "untrained";
    set.config = config;
    set.rule = run.rules.at(cls);
    for (const PeerFrame& f : frames) set.frameIds.push_back(f.id);
    set.frames = outcomes;
    out.sets.push_back(std::move(set));
  }
  return out;
}

}  // namespace fusedet::boosting
