// SPDX-License-Identifier: Apache-2.0
#pragma once
// The expected range of the LMS simulator's default scene, computed independently of the
// simulator: side walls at x = +-3 m, front wall at y = 5 m, a post of radius 0.2 m at (0.5, 2.0);
// the scanner at the origin looking along +y. Shared by the simulator tests and the MRPT peer test.

#include <algorithm>
#include <cmath>

namespace fusedet::testing {

inline double expectedRoomRange(double deg) {
  const double a = deg * M_PI / 180.0, c = std::cos(a), s = std::sin(a);
  double best = 1e9;
  if (c > 1e-9) best = std::min(best, 3.0 / c);
  if (c < -1e-9) best = std::min(best, -3.0 / c);
  if (s > 1e-9) best = std::min(best, 5.0 / s);
  // Post: distance along the ray to the circle |p - (0.5, 2)| = 0.2.
  const double along = 0.5 * c + 2.0 * s;
  const double off2 = 0.5 * 0.5 + 2.0 * 2.0 - along * along;
  if (off2 <= 0.04 && along > 0) best = std::min(best, along - std::sqrt(0.04 - off2));
  return best;
}

}  // namespace fusedet::testing
