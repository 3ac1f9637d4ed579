// SPDX-License-Identifier: Apache-2.0
#pragma once
// TiltUnits: drive position counts <-> tilt angle, from the config's `tilt:` keys
// (counts_per_rev, gear_ratio, zero_offset_counts): angle = 2 pi (counts - zero) / (cpr * gear).

#include <cmath>
#include <cstdint>
#include <numbers>

namespace fusedet::drivers::canopen {

struct TiltUnits {
  int countsPerRev = 4096;     // encoder counts per motor revolution
  double gearRatio = 50.0;     // motor revolutions per tilt-axis revolution
  std::int32_t zeroOffsetCounts = 0;

  double countsPerRad() const { return countsPerRev * gearRatio / (2.0 * std::numbers::pi); }
  double toRad(std::int32_t counts) const { return (static_cast<double>(counts) - zeroOffsetCounts) / countsPerRad(); }
  std::int32_t toCounts(double rad) const {
    return static_cast<std::int32_t>(std::lround(rad * countsPerRad() + zeroOffsetCounts));
  }
  // Speeds and accelerations [rad/s, rad/s^2] -> [counts/s, counts/s^2], at least 1.
  std::uint32_t rate(double radPerS) const {
    return static_cast<std::uint32_t>(std::max(1.0, std::round(std::abs(radPerS) * countsPerRad())));
  }
};

}  // namespace fusedet::drivers::canopen
