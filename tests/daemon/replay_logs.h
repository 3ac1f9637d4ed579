// SPDX-License-Identifier: Apache-2.0
#pragma once
// Sensor logs for the daemon tests: synthesised at run time by the synth-log library from the
// KITTI frames (last third of drive 0005) in ../shared/data (procedural scene when there is no KITTI data) and kept
// in build/logs/ (never in the source tree: KITTI licence). A log older than the test binary is
// made again, so a changed synthesiser never leaves a stale cache behind.

#include <unistd.h>

#include <filesystem>
#include <string>

#include "fusedet/fusion/synthesis/synth_log.h"

namespace fusedet::testlogs {

inline bool haveKitti() { return std::filesystem::exists(std::filesystem::path(FUSEDET_DATA_DIR) / "kitti" / "velodyne"); }

// A log of `strokes` strokes (one fused stack each).
inline std::filesystem::path daemonTestLog(int strokes) {
  namespace fs = std::filesystem;
  fusion::SynthOptions options;
  if (haveKitti()) options.kitti = fs::path(FUSEDET_DATA_DIR) / "kitti";
  options.frames = strokes;
  const fs::path dir = fs::path(FUSEDET_BINARY_DIR) / "logs";
  fs::create_directories(dir);
  const fs::path log =
      dir / ("daemon-test-" + std::string(haveKitti() ? "kitti" : "procedural") + "-" + std::to_string(strokes) + ".mcap");
  std::error_code ec;
  const auto binary = fs::last_write_time("/proc/self/exe", ec);
  if (!ec && fs::exists(log) && fs::last_write_time(log) > binary) return log;
  // Written aside and renamed: a test running in parallel sees a whole file or none.
  const fs::path partial = log.string() + ".part" + std::to_string(::getpid());
  fusion::synthesizeLog(options, partial);
  fs::rename(partial, log);
  return log;
}

}  // namespace fusedet::testlogs
