// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scene for the LMS 291 simulator: a rectangular room seen from a scanner on the back wall's
// axis, with round posts. The scanner looks along +y; beam angles run counter-clockwise from
// 0 = +x (right) to 180 deg = -x (left), as the LMS counts them.

#include <cstdint>
#include <vector>

namespace fusedet::drivers::lms291::sim {

struct Post {
  double x = 0, y = 0, radius = 0;  // [m]
};

struct SceneOptions {
  double halfWidth = 3.0;  // side walls at x = +-halfWidth [m]
  double depth = 5.0;      // front wall at y = depth [m]
  std::vector<Post> posts{{0.5, 2.0, 0.2}};
  double wallRemission = 0.3;  // [0..1]
  double postRemission = 0.9;
};

struct Hit {
  double range = 0;      // [m], 0 = nothing within 1 km
  double remission = 0;  // [0..1]
};

class Scene {
 public:
  explicit Scene(SceneOptions o = {}) : o_(std::move(o)) {}
  Hit cast(double angleRad) const;
  const SceneOptions& options() const { return o_; }

 private:
  SceneOptions o_;
};

}  // namespace fusedet::drivers::lms291::sim
