// SPDX-License-Identifier: Apache-2.0
#pragma once
// Sweep: the 3D points of one tilt sweep of the nodding laser (or one Velodyne turn in KITTI).

#include <cstdint>
#include <vector>

#include "fusedet/core/stamp.h"

namespace fusedet::fusion {

struct SweepPoint {
  float x = 0, y = 0, z = 0;  // [m] in the frame named by Sweep::frame
  float remission = 0;        // [0, 1]
  std::int64_t stampNs = 0;   // CLOCK_MONOTONIC of the beam (0 if unknown)
};

struct Sweep {
  std::uint64_t id = 0;
  Stamp start;  // first beam
  Stamp end;    // last beam
  enum class Frame : std::uint8_t { kRobot, kVelodyne } frame = Frame::kRobot;
  std::vector<SweepPoint> points;

  Stamp middle() const { return Stamp{start.ns + (end.ns - start.ns) / 2}; }
  std::size_t size() const { return points.size(); }
};

}  // namespace fusedet::fusion
