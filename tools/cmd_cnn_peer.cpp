// SPDX-License-Identifier: Apache-2.0
// fusedet cnn-peer: a pretrained COCO detector alone (camera only, never trained on KITTI) on the
// labelled KITTI frames the cascades are scored on - per class F and AP with 95 % bootstrap
// intervals, counts and ms per frame. Rules: fusedet/experiments/cnn_peer.h (the run),
// fusedet/fusion/neural/coco_detections.h (COCO classes -> car, person, bike), boost/evaluate (KITTI
// matching, AP, intervals).

#include <cstdio>
#include <filesystem>
#include <memory>

#include "command.h"
#include "data_dir.h"
#include "experiments/claims.h"
#include "experiments/data.h"
#include "experiments/text.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/experiments/cnn_peer.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;

struct CnnPeerOptions {
  std::string kind;
  std::vector<fs::path> files;
  std::string input;
  fs::path data = defaultDataDir();
  std::vector<std::string> classes = {"car", "person", "bike"};
  double minIou = 0;
  fusion::CocoDetectionRule rule;
  std::size_t resamples = 1000;
  std::uint64_t seed = 1;
  int threads = 1;
  fs::path outcomes;
  std::string config;
};

std::string commandLine(const CnnPeerOptions& o) {
  std::string c = "fusedet cnn-peer --kind " + o.kind;
  for (const fs::path& f : o.files) c += " --model " + f.string();
  c += " --input " + o.input + " --data " + o.data.string() + " --min-iou " + experiments::shortNum(o.minIou) +
       " --min-score " + experiments::shortNum(o.rule.minScore);
  return c;
}

int runCnnPeer(const CnnPeerOptions& o) {
  const fusion::NetworkSpec spec{fusion::parseNetworkKind(o.kind), o.files, fusion::parseInputSize(o.input), o.threads};
  fusion::Network network(spec);
  const std::vector<fs::path> drives = experiments::kittiDrives(o.data);
  if (drives.empty())
    throw std::runtime_error(o.data.string() + ": no KITTI drive (image_2/, label_2/, velodyne/, calib/) here or below");
  std::vector<boosting::PeerFrame> frames;
  for (const fs::path& d : drives)
    for (const std::string& id : fusion::listKittiFrames(d))
      frames.push_back({d.filename().string() + "/" + id, d / "image_2" / (id + ".png"),
                        fusion::readKittiLabels(d / "label_2" / (id + ".txt"))});
  std::printf("network   %s\nframes    %zu from %zu KITTI folders under %s\n", network.identity().text().c_str(),
              frames.size(), drives.size(), o.data.c_str());
  std::fflush(stdout);
  const auto matchFor = [&](const std::string& c) {
    return boosting::matchConfigFor(c, boosting::VanPolicy::kIgnore, o.minIou);
  };
  const boosting::CnnPeerRun run = boosting::runCnnPeer(network, frames, o.classes, matchFor, o.rule);
  boosting::BootstrapConfig boot;
  boot.resamples = o.resamples;
  boot.seed = o.seed;
  std::printf("rule      score >= %s, NMS IoU %s, rider covers >= %s of a bicycle; KITTI moderate, van ignored\n",
              experiments::shortNum(o.rule.minScore).c_str(), experiments::shortNum(o.rule.nmsIou).c_str(),
              experiments::shortNum(o.rule.minRiderCoverage).c_str());
  std::printf("speed     %.1f ms per frame wall, %.1f ms CPU (network and decoding, %d OpenCV thread%s)\n\n",
              run.msPerFrame, run.cpuMsPerFrame, o.threads, o.threads == 1 ? "" : "s");
  std::printf("| class | hit at IoU | F [95 %% CI] | AP [95 %% CI] | hits / false alarms / misses |\n|---|---:|---:|---:|---:|\n");
  for (const std::string& c : o.classes) {
    const experiments::Measured m = experiments::measure(run.frames.at(c), boot);
    const boosting::Counts& n = run.counts.at(c);
    std::printf("| %s | %s | %s | %s | %zu / %zu / %zu |\n", c.c_str(), experiments::shortNum(matchFor(c).minIou).c_str(),
                experiments::formatEstimate(m.f).c_str(), experiments::formatEstimate(m.ap).c_str(), n.hits,
                n.falseAlarms, n.misses);
  }
  if (!o.outcomes.empty()) {
    const std::string config = o.config.empty() ? o.files.front().stem().string() : o.config;
    boosting::writeOutcomes(o.outcomes, boosting::cnnPeerOutcomes(run, frames, config, commandLine(o)));
    std::printf("\noutcomes  %s (protocol untrained, configuration %s; pair with `fusedet compare RUN %s --protocol "
                "lodo --protocol-b untrained --config all --config-b %s`)\n",
                o.outcomes.c_str(), config.c_str(), o.outcomes.c_str(), config.c_str());
  }
  return 0;
}

const bool registered = registerCommand(
    "cnn-peer", "A pretrained COCO detector alone on the labelled KITTI frames: per class F and AP with intervals",
    [](CLI::App& app) {
      auto o = std::make_shared<CnnPeerOptions>();
      app.add_option("--kind", o->kind, "network kind: darknet (cfg + weights) or yolov5-onnx (one .onnx)")
          ->required()
          ->check(CLI::IsMember({"darknet", "yolov5-onnx"}));
      app.add_option("--model", o->files, "the network's file(s): darknet: the .cfg then the .weights; yolov5-onnx: the .onnx")
          ->required();
      app.add_option("--input", o->input, "input size WxH the network runs at (an ONNX export has one fixed size)")
          ->required();
      app.add_option("--data", o->data, "a KITTI drive or a folder of them (default $FUSEDET_DATA or ../shared/data)")
          ->capture_default_str();
      app.add_option("--classes", o->classes, "classes to score (car, person, bike)")
          ->delimiter(',')
          ->check(CLI::IsMember({"car", "person", "bike"}))
          ->capture_default_str();
      app.add_option("--min-iou", o->minIou,
                     "a detection hits a label at IoU >= this; 0 = the KITTI devkit's (car 0.7, person and bike 0.5)")
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
      app.add_option("--min-score", o->rule.minScore, "class score a detection needs (the operating point)")
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
      app.add_option("--resamples", o->resamples, "bootstrap resamples")->capture_default_str();
      app.add_option("--seed", o->seed, "bootstrap seed")->capture_default_str();
      app.add_option("--outcomes", o->outcomes,
                     "also write the per-frame outcomes to this file (docs/outcomes-format.md) for `fusedet compare`");
      app.add_option("--config-name", o->config, "configuration name in --outcomes (default: the first model file's stem)");
      app.add_option("--threads", o->threads, "OpenCV threads while the network runs (1: the same output every run)")
          ->check(CLI::Range(1, 64))
          ->capture_default_str();
      app.footer(
          "COCO person, bicycle and car become person, bike and car (fusedet/fusion/neural/coco_detections.h): a person "
          "covering >= 0.3 of a bicycle's box is a cyclist (bike, the union box). Frames: every labelled frame of the "
          "KITTI folders `fusedet experiments` imports, scored with the same KITTI moderate rules.\n\n"
          "Examples:\n"
          "  fusedet cnn-peer --kind yolov5-onnx --model ../shared/models/yolov5n_256x832.onnx --input 832x256\n"
          "  fusedet cnn-peer --kind darknet --model ../shared/models/yolo-fastest-1.1-xl.cfg "
          "--model ../shared/models/yolo-fastest-1.1-xl.weights --input 832x256 --min-iou 0.5");
      return [o] { return runCnnPeer(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
