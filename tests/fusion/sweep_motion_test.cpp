// SPDX-License-Identifier: Apache-2.0
// The scanner's motion during a sweep: a spinning scanner simulated here (its beam time solved for
// every world point, sharing no code with deskewSweep) and scan matching between two sweeps of a
// static scene seen from known poses.

#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <stdexcept>
#include <vector>

#include "fusedet/fusion/calibration/sweep_motion.h"

namespace fusedet::fusion {
namespace {

struct P2 {
  double x, y, z;
};

// Walls in three directions, poles and a few boxes' faces, 5-30 m away, above the road.
std::vector<P2> scene() {
  std::vector<P2> w;
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> h(-1.2, 2.5);
  for (double s = -25; s <= 25; s += 0.15) {
    w.push_back({s, 12.0, h(rng)});           // wall on the left, along x
    w.push_back({s * 0.6, -9.0 + 0.2 * s, h(rng)});  // wall on the right, slanted
    if (s > -10 && s < 10) w.push_back({28.0 + 0.3 * s, s, h(rng)});  // wall ahead, slanted
  }
  const P2 poles[] = {{8, 3, 0}, {14, -4, 0}, {-9, 5, 0}, {20, 6, 0}, {-15, -5, 0}, {6, -6, 0}};
  for (const P2& c : poles)
    for (int k = 0; k < 120; ++k) {
      const double a = 2 * M_PI * k / 40.0;
      w.push_back({c.x + 0.2 * std::cos(a), c.y + 0.2 * std::sin(a), -1.2 + 0.03 * k});
    }
  return w;
}

// A world point as a scanner turning clockwise once in `turn` seconds measures it: the scanner at
// time t sits at v t (frame-0 coordinates) turned by w t, and its beam points at azimuth -2 pi t / turn;
// t solved by fixed-point iteration, then the point in the scanner's frame at t.
SweepPoint measured(const P2& p, double vx, double vy, double w, double turn) {
  double t = 0;
  double lx = 0, ly = 0;
  for (int k = 0; k < 50; ++k) {
    const double dx = p.x - vx * t, dy = p.y - vy * t, c = std::cos(-w * t), s = std::sin(-w * t);
    lx = c * dx - s * dy;
    ly = s * dx + c * dy;
    t = -std::atan2(ly, lx) * turn / (2 * M_PI);
  }
  SweepPoint q;
  q.x = static_cast<float>(lx);
  q.y = static_cast<float>(ly);
  q.z = static_cast<float>(p.z);
  return q;
}

TEST(SweepMotion, DeskewPutsASpinningScannersPointsBackWhereTheyWere) {
  const std::vector<P2> world = scene();
  const double vx = 11.0, vy = 0.4, w = -0.25, turn = 0.1;  // 40 km/h, turning right at 14 deg/s
  Sweep sweep;
  for (const P2& p : world) sweep.points.push_back(measured(p, vx, vy, w, turn));
  double before = 0;
  for (std::size_t i = 0; i < world.size(); ++i)
    before = std::max(before, std::hypot(sweep.points[i].x - world[i].x, sweep.points[i].y - world[i].y));
  ASSERT_GT(before, 0.4);  // the shear is there: up to half a turn at 11 m/s

  Sweep right = sweep, wrong = sweep;
  deskewSweep(right, {vx, vy, w}, turn, SpinSense::kClockwise);
  deskewSweep(wrong, {vx, vy, w}, turn, SpinSense::kCounterClockwise);
  double after = 0, wrongSense = 0;
  for (std::size_t i = 0; i < world.size(); ++i) {
    after = std::max(after, std::hypot(right.points[i].x - world[i].x, right.points[i].y - world[i].y));
    wrongSense = std::max(wrongSense, std::hypot(wrong.points[i].x - world[i].x, wrong.points[i].y - world[i].y));
    EXPECT_EQ(right.points[i].z, sweep.points[i].z);
  }
  EXPECT_LT(after, 2e-5 * 30 + 1e-5);  // float rounding at 30 m
  EXPECT_GT(wrongSense, 0.4);
}

TEST(SweepMotion, ScanMatchingRecoversAPlanarMotion) {
  const std::vector<P2> world = scene();
  // Later pose: 1.2 m ahead, 0.1 m left, turned 3 degrees left, 0.3 s after the earlier one at the origin.
  const double px = 1.2, py = 0.1, yaw = 3.0 * M_PI / 180, seconds = 0.3;
  Sweep earlier, later;
  const double c = std::cos(-yaw), s = std::sin(-yaw);
  for (const P2& p : world) {
    earlier.points.push_back({static_cast<float>(p.x), static_cast<float>(p.y), static_cast<float>(p.z), 0, 0});
    const double dx = p.x - px, dy = p.y - py;
    later.points.push_back({static_cast<float>(c * dx - s * dy), static_cast<float>(s * dx + c * dy), static_cast<float>(p.z), 0, 0});
  }
  PlanarMatchOptions o;
  o.stride = 1;
  const PlanarMotion m = estimatePlanarMotion(earlier, later, seconds, o);
  EXPECT_NEAR(m.vx, px / seconds, 0.02 * px / seconds);
  EXPECT_NEAR(m.vy, py / seconds, 0.05);
  EXPECT_NEAR(m.yawRate, yaw / seconds, 0.02 * yaw / seconds);
}

TEST(SweepMotion, SweepsWithNothingInCommonAreAClearError) {
  Sweep a, b;
  for (int i = 0; i < 500; ++i) {
    a.points.push_back({10.f + 0.01f * static_cast<float>(i), 5.f, 0.f, 0, 0});
    b.points.push_back({-10.f - 0.01f * static_cast<float>(i), -5.f, 0.f, 0, 0});
  }
  try {
    estimatePlanarMotion(a, b, 0.1);
    FAIL() << "no pairs, yet a motion";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("point pairs"), std::string::npos) << e.what();
  }
  EXPECT_THROW(estimatePlanarMotion(a, a, 0.0), std::invalid_argument);
}

}  // namespace
}  // namespace fusedet::fusion
