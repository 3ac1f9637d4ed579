// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/messages.h"

#include <gtest/gtest.h>

#include <cmath>

using fusedet::drivers::LaserScan;

TEST(LaserScan, BeamAnglesAndStampsFollowTheScanGeometry) {
  LaserScan s;
  s.stamp = fusedet::Stamp{1'000'000'000};
  s.startAngle = 0;
  s.angleStep = M_PI / 360;  // 0.5 deg
  s.beamDuration = (1.0 / 75.0 / 2.0) / 360.0;  // 180 deg = half a mirror turn
  s.ranges.assign(361, 1.0f);
  EXPECT_EQ(s.size(), 361u);
  EXPECT_NEAR(s.beamAngle(180), M_PI / 2, 1e-12);  // straight ahead
  EXPECT_NEAR(s.beamAngle(360), M_PI, 1e-12);
  // The last beam of a 180 deg half turn comes 1/150 s after the first.
  EXPECT_NEAR(double(s.beamStamp(360).ns - s.stamp.ns), 1e9 / 75.0 / 2.0, 1.0);
}

TEST(PixelFormat, Names) {
  EXPECT_EQ(fusedet::drivers::toString(fusedet::drivers::PixelFormat::kYuyv), "YUYV");
  EXPECT_EQ(fusedet::drivers::toString(fusedet::drivers::PixelFormat::kMjpeg), "MJPEG");
}
