// SPDX-License-Identifier: Apache-2.0
#pragma once
// Offline replay: a sensor log through the daemon's own pipeline (replayParts + Pipeline, exactly
// what fusedetd runs with replay.file set) as fast as the machine allows, without dropping a
// stack, with the log's recorded stamps - for batch processing, measurements and tests
// (`fusedet replay`). Every stack's result is handed over in stack order; encoded with
// protocol.h resultToJson() it is the `detections` line a subscribed client would get.

#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/pipeline.h"
#include "fusedet/daemon/stack_detector.h"

namespace fusedet::daemon {

struct OfflineReplayReport {
  PipelineCounters counters;  // at the end: stacks fused and detected, sweeps, errors
  std::string damage;         // what is wrong with the log ("" when intact)
};

// `config` supplies detection, models and tracking (relative paths against configFile's folder);
// the rig comes from the log (rig.h replayRig). Its replay section is replaced: realtime false,
// restamp false, one pass. onResult runs on the detection thread, one stack after the other.
// Throws std::runtime_error naming the log or model file when they cannot be used.
OfflineReplayReport replayOffline(Config config, const std::filesystem::path& configFile,
                                  const std::filesystem::path& log,
                                  const std::function<void(const StackResult&)>& onResult);
// The same with `detector` in place of the config's models (none are loaded): e.g. one that keeps
// every fused stack (`fusedet dataset from-log`).
OfflineReplayReport replayOffline(Config config, const std::filesystem::path& configFile,
                                  const std::filesystem::path& log, std::shared_ptr<const StackDetector> detector,
                                  const std::function<void(const StackResult&)>& onResult);

}  // namespace fusedet::daemon
