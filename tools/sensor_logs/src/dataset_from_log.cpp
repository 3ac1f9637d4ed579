// SPDX-License-Identifier: Apache-2.0
#include "fusedet/sensor_logs/dataset_from_log.h"

#include <cstdio>
#include <functional>
#include <opencv2/imgcodecs.hpp>
#include <stdexcept>

#include "fusedet/core/dataset.h"
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/offline_replay.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/camera_layers.h"

namespace fusedet::sensor_logs {
namespace fs = std::filesystem;

namespace {

// The pipeline's detection step, used as a tap: it sees every fused stack in order and finds nothing.
class StackTap : public daemon::StackDetector {
 public:
  explicit StackTap(std::function<void(const LayerStack&)> take) : take_(std::move(take)) {}
  std::vector<Detection> detect(const LayerStack& stack) const override {
    take_(stack);
    return {};
  }
  std::vector<std::string> classes() const override { return {}; }

 private:
  std::function<void(const LayerStack&)> take_;
};

}  // namespace

FromLogReport datasetFromLog(const fs::path& log, const fs::path& out, const FromLogOptions& options) {
  if (options.every == 0) throw std::invalid_argument("--every must be >= 1");
  if (!(options.strideSeconds >= 0)) throw std::invalid_argument("--stride-s must be >= 0");
  const drivers::logs::LogSource probe(log);
  const auto rig = probe.rig();
  if (!rig) throw std::runtime_error(log.string() + ": no fusedet.config metadata (the rig) to fuse it with");
  const daemon::Config config = daemon::parseConfig(rig->configYaml, log.string() + ":fusedet.config");

  FromLogReport report;
  report.group = options.group.empty() ? toIdSegment(log.stem().string(), "log") : options.group;
  std::int64_t lastKeptNs = 0;
  bool keptAny = false;
  std::string error;  // the tap runs on the detection thread: keep its first error for the caller
  auto take = [&](const LayerStack& stack) {
    const std::uint64_t n = report.stacks++;
    if (!error.empty() || n % options.every != 0) return;
    if (keptAny && options.strideSeconds > 0 &&
        static_cast<double>(stack.stamp.ns - lastKeptNs) < options.strideSeconds * 1e9)
      return;
    char frame[32];
    std::snprintf(frame, sizeof frame, "%06llu", static_cast<unsigned long long>(stack.id));
    DatasetItem item;
    item.id = report.group + "/" + frame;
    item.group = report.group;
    item.stack = stack;
    item.stack.source = log.filename().string() + "#" + std::to_string(stack.id);
    try {
      writeDatasetItem(out, item);
      if (options.images) {
        const fs::path png = out / "images" / (item.id + ".png");
        fs::create_directories(png.parent_path());
        if (!cv::imwrite(png.string(), fusion::cameraImage(stack))) throw std::runtime_error(png.string() + ": cannot write");
      }
    } catch (const std::exception& e) {
      error = e.what();
      return;
    }
    ++report.written;
    lastKeptNs = stack.stamp.ns;
    keptAny = true;
  };
  const daemon::OfflineReplayReport r =
      daemon::replayOffline(config, log, log, std::make_shared<const StackTap>(take), [](const daemon::StackResult&) {});
  if (!error.empty()) throw std::runtime_error(error);
  report.damage = r.damage;
  return report;
}

}  // namespace fusedet::sensor_logs
