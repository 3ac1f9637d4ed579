// SPDX-License-Identifier: Apache-2.0
#pragma once
// datasetFromLog: a recorded sensor log as data set items (docs/dataset-format.md) for labelling
// and training on a robot's own data. The log is replayed through fusedetd's own pipeline
// (fusedet/daemon/offline_replay.h: the live decoders, sweep assembly, frame pairing and fusion,
// configured from the rig the log carries: its calibration), and every chosen fused stack becomes
// an item "<group>/<stack id>" with no labels, plus its camera image as <out>/images/<id>.png for
// labelling tools (the names `fusedet dataset import` matches).

#include <cstdint>
#include <filesystem>
#include <string>

namespace fusedet::sensor_logs {

struct FromLogOptions {
  std::string group;          // empty: the log's file name without extension
  std::uint64_t every = 1;    // keep every n-th stack
  double strideSeconds = 0;   // > 0: keep a stack only this long after the last kept one (camera stamps)
  bool images = true;         // write <out>/images/<id>.png
};

struct FromLogReport {
  std::uint64_t stacks = 0;   // fused stacks the replay made
  std::uint64_t written = 0;  // items written
  std::string group;
  std::string damage;         // what is wrong with the log ("" when intact)
};

// Throws std::runtime_error naming the log when it cannot be replayed (not MCAP, no rig).
FromLogReport datasetFromLog(const std::filesystem::path& log, const std::filesystem::path& out,
                             const FromLogOptions& options);

}  // namespace fusedet::sensor_logs
