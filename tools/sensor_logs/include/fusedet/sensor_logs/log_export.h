// SPDX-License-Identifier: Apache-2.0
#pragma once
// Exports of a sensor log for other tools: camera frames as PNG files, sweeps as PLY point
// clouds. Frames are decoded as live (decodeCameraFrame); sweeps are the log's /sweep/points
// messages if it has them, else assembled from the replayed raw laser and tilt streams with the
// given rig (the log's own, see fusedet/daemon/rig.h).

#include <cstdint>
#include <filesystem>

#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/sweep_assembler.h"

namespace fusedet::sensor_logs {

// <dir>/frame_<sequence>_<stamp ns>.png per camera frame; returns the count. Throws on an
// unreadable log, an undecodable frame (naming it) or an unwritable directory.
std::uint64_t exportFramesPng(const std::filesystem::path& log, const std::filesystem::path& dir);

// <dir>/sweep_<n>_<start ns>.ply (ASCII PLY: x y z remission, laser base frame) per sweep.
std::uint64_t exportSweepsPly(const std::filesystem::path& log, const drivers::logs::SensorReplayConfig& replay,
                              const fusion::SweepConfig& sweeps, const std::filesystem::path& dir);

// One sweep as ASCII PLY (vertex x y z remission).
void writePly(const fusion::Sweep& sweep, const std::filesystem::path& file);

}  // namespace fusedet::sensor_logs
