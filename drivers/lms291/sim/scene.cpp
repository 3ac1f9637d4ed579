// SPDX-License-Identifier: Apache-2.0
#include "scene.h"

#include <cmath>

namespace fusedet::drivers::lms291::sim {

Hit Scene::cast(double angleRad) const {
  const double dx = std::cos(angleRad), dy = std::sin(angleRad);
  Hit best{1e3, 0};
  auto consider = [&](double t, double remission) {
    if (t > 1e-9 && t < best.range) best = Hit{t, remission};
  };
  if (dx > 1e-12) consider(o_.halfWidth / dx, o_.wallRemission);
  if (dx < -1e-12) consider(-o_.halfWidth / dx, o_.wallRemission);
  if (dy > 1e-12) consider(o_.depth / dy, o_.wallRemission);
  for (const Post& p : o_.posts) {
    // |t d - c|^2 = r^2  =>  t = d.c - sqrt((d.c)^2 - |c|^2 + r^2)
    const double b = dx * p.x + dy * p.y;
    const double disc = b * b - (p.x * p.x + p.y * p.y) + p.radius * p.radius;
    if (disc >= 0) consider(b - std::sqrt(disc), o_.postRemission);
  }
  if (best.range >= 1e3) return Hit{};
  return best;
}

}  // namespace fusedet::drivers::lms291::sim
