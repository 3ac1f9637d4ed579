// SPDX-License-Identifier: Apache-2.0
#pragma once
// Stamp: a CLOCK_MONOTONIC time point in nanoseconds, the one clock every message in fusedet uses.

#include <compare>
#include <cstdint>
#include <string>

namespace fusedet {

struct Stamp {
  std::int64_t ns = 0;  // nanoseconds since an arbitrary (boot-time) epoch, CLOCK_MONOTONIC

  static Stamp now();  // CLOCK_MONOTONIC, read as close to the caller as possible
  static constexpr Stamp fromSeconds(double s) { return Stamp{static_cast<std::int64_t>(s * 1e9)}; }

  constexpr double seconds() const { return static_cast<double>(ns) * 1e-9; }
  constexpr Stamp operator+(std::int64_t dns) const { return Stamp{ns + dns}; }
  constexpr Stamp operator-(std::int64_t dns) const { return Stamp{ns - dns}; }
  constexpr std::int64_t operator-(Stamp other) const { return ns - other.ns; }
  constexpr auto operator<=>(const Stamp&) const = default;

  std::string toString() const;  // "12345.678901234" seconds, fixed 9 decimals
};

}  // namespace fusedet
