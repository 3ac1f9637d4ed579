// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/offline_replay.h"

#include <chrono>
#include <stdexcept>
#include <thread>

#include "fusedet/daemon/service_parts.h"

namespace fusedet::daemon {

namespace {

OfflineReplayReport run(Config config, const std::filesystem::path& configFile, const std::filesystem::path& log,
                        std::shared_ptr<const StackDetector> detector,
                        const std::function<void(const StackResult&)>& onResult) {
  config.replay.file = std::filesystem::absolute(log).string();
  config.replay.realtime = false;
  config.replay.restamp = false;
  config.replay.atEnd = "exit";
  ServiceParts parts = replayParts(std::move(config), configFile, detector == nullptr);
  if (detector) parts.detector = std::move(detector);
  Pipeline pipeline(pipelineSetup(parts), parts.detector,
                    [&onResult](std::shared_ptr<const StackResult> r) { onResult(*r); });
  pipeline.start();
  for (auto& s : parts.sources) s->start(pipeline);
  auto done = [&] {
    for (const auto& s : parts.sources)
      if (!s->finished()) return false;
    return pipeline.idle();
  };
  while (!done()) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  for (auto& s : parts.sources) s->stop();
  pipeline.stop(std::chrono::steady_clock::now() + std::chrono::seconds(10));
  OfflineReplayReport report;
  report.counters = pipeline.counters();
  for (const auto& s : parts.sources)
    for (const SensorHealth& h : s->health())
      if (!h.lastError.empty()) report.damage += (report.damage.empty() ? "" : "; ") + h.lastError;
  return report;
}

}  // namespace

OfflineReplayReport replayOffline(Config config, const std::filesystem::path& configFile,
                                  const std::filesystem::path& log,
                                  const std::function<void(const StackResult&)>& onResult) {
  return run(std::move(config), configFile, log, nullptr, onResult);
}

OfflineReplayReport replayOffline(Config config, const std::filesystem::path& configFile,
                                  const std::filesystem::path& log, std::shared_ptr<const StackDetector> detector,
                                  const std::function<void(const StackResult&)>& onResult) {
  if (!detector) throw std::invalid_argument("replayOffline: no detector");
  return run(std::move(config), configFile, log, std::move(detector), onResult);
}

}  // namespace fusedet::daemon
