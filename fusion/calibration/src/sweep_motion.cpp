// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/sweep_motion.h"

#include <Eigen/Dense>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <unordered_map>
#include <vector>

namespace fusedet::fusion {
namespace {

// Nearest neighbour among fixed points through a grid of cells of the pair distance: a point's
// neighbour within that distance lies in its cell or one of the eight around it.
class PlanarGrid {
 public:
  PlanarGrid(const std::vector<Eigen::Vector3d>& points, double cell) : points_(points), cell_(cell) {
    for (std::size_t i = 0; i < points.size(); ++i) cells_[key(cellOf(points[i].x()), cellOf(points[i].y()))].push_back(i);
  }
  // Index of the nearest point within maxDistance, or -1.
  std::int64_t nearest(const Eigen::Vector3d& p, double maxDistance) const {
    const std::int64_t cx = cellOf(p.x()), cy = cellOf(p.y());
    double best = maxDistance * maxDistance;
    std::int64_t found = -1;
    for (std::int64_t dx = -1; dx <= 1; ++dx)
      for (std::int64_t dy = -1; dy <= 1; ++dy) {
        const auto it = cells_.find(key(cx + dx, cy + dy));
        if (it == cells_.end()) continue;
        for (std::size_t i : it->second) {
          const double d = (points_[i] - p).squaredNorm();
          if (d < best) {
            best = d;
            found = static_cast<std::int64_t>(i);
          }
        }
      }
    return found;
  }

 private:
  std::int64_t cellOf(double v) const { return static_cast<std::int64_t>(std::floor(v / cell_)); }
  static std::uint64_t key(std::int64_t x, std::int64_t y) {
    return (static_cast<std::uint64_t>(x) << 32) ^ (static_cast<std::uint64_t>(y) & 0xffffffffu);
  }
  const std::vector<Eigen::Vector3d>& points_;
  double cell_;
  std::unordered_map<std::uint64_t, std::vector<std::size_t>> cells_;
};

std::vector<Eigen::Vector3d> matchable(const Sweep& sweep, const PlanarMatchOptions& o, int stride) {
  std::vector<Eigen::Vector3d> out;
  for (std::size_t i = 0; i < sweep.points.size(); i += static_cast<std::size_t>(stride)) {
    const SweepPoint& p = sweep.points[i];
    const double r = std::hypot(double(p.x), double(p.y));
    if (r >= o.minRange && r <= o.maxRange && p.z > o.minHeight) out.emplace_back(p.x, p.y, p.z);
  }
  return out;
}

}  // namespace

PlanarMotion estimatePlanarMotion(const Sweep& earlier, const Sweep& later, double seconds, const PlanarMatchOptions& options) {
  if (!(seconds > 0)) throw std::invalid_argument("planar motion: the time between the sweeps must be positive");
  const std::vector<Eigen::Vector3d> fixed = matchable(earlier, options, 1);
  const std::vector<Eigen::Vector3d> moving = matchable(later, options, std::max(1, options.stride));
  const PlanarGrid grid(fixed, options.maxPairDistance);
  // later's frame -> earlier's frame: p_earlier = R p_later + t (rotation about z only).
  Eigen::Matrix2d R = Eigen::Matrix2d::Identity();
  Eigen::Vector2d t = Eigen::Vector2d::Zero();
  for (int it = 0; it < options.iterations; ++it) {
    std::vector<Eigen::Vector2d> a, b;
    for (const Eigen::Vector3d& p : moving) {
      Eigen::Vector3d q;
      q << R * p.head<2>() + t, p.z();
      const std::int64_t k = grid.nearest(q, options.maxPairDistance);
      if (k < 0) continue;
      a.push_back(q.head<2>());
      b.push_back(fixed[static_cast<std::size_t>(k)].head<2>());
    }
    if (a.size() < 100)
      throw std::invalid_argument("planar motion: " + std::to_string(a.size()) +
                                  " point pairs between the sweeps (need 100): too far apart or too little structure");
    Eigen::Vector2d ca = Eigen::Vector2d::Zero(), cb = Eigen::Vector2d::Zero();
    for (std::size_t i = 0; i < a.size(); ++i) {
      ca += a[i];
      cb += b[i];
    }
    ca /= static_cast<double>(a.size());
    cb /= static_cast<double>(b.size());
    Eigen::Matrix2d H = Eigen::Matrix2d::Zero();
    for (std::size_t i = 0; i < a.size(); ++i) H += (a[i] - ca) * (b[i] - cb).transpose();
    // The best rotation of a 2D point set: its angle is atan2 of H's antisymmetric over its symmetric part.
    const double angle = std::atan2(H(0, 1) - H(1, 0), H(0, 0) + H(1, 1));
    const Eigen::Matrix2d Rk = Eigen::Rotation2Dd(angle).toRotationMatrix();
    R = Rk * R;
    t = Rk * t + (cb - Rk * ca);
  }
  // The frame moved by t (and turned by R) from earlier to later.
  PlanarMotion m;
  m.vx = t.x() / seconds;
  m.vy = t.y() / seconds;
  m.yawRate = std::atan2(R(1, 0), R(0, 0)) / seconds;
  return m;
}

void deskewSweep(Sweep& sweep, const PlanarMotion& motion, double turnSeconds, SpinSense sense) {
  const double perRadian = turnSeconds / (2 * M_PI) * (sense == SpinSense::kClockwise ? -1.0 : 1.0);
  for (SweepPoint& p : sweep.points) {
    const double t = perRadian * std::atan2(double(p.y), double(p.x));  // [s] after the beam pointed ahead
    // The scanner's pose at t in the frame at 0 (constant velocity, small turn): turned by yawRate t,
    // moved by the velocity times t.
    const double yaw = motion.yawRate * t, c = std::cos(yaw), s = std::sin(yaw);
    const double x = c * p.x - s * p.y + motion.vx * t, y = s * p.x + c * p.y + motion.vy * t;
    p.x = static_cast<float>(x);
    p.y = static_cast<float>(y);
  }
}

}  // namespace fusedet::fusion
