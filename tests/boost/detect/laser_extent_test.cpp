// SPDX-License-Identifier: Apache-2.0
// Laser-extent box refinement (fusedet/boost/laser_extent.h) on distance layers drawn by hand; the expected
// boxes are worked out from the rule in the comments.

#include "fusedet/boost/laser_extent.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

// Reference grid refW x refH, distance layer cols x rows: background at 30 m, an object at 10 m
// over columns [c0, c1] and rows 10..39 of the layer.
LayerStack scene(int refW, int refH, int cols, int rows, int c0, int c1) {
  LayerStack s(refW, refH);
  cv::Mat1f d(rows, cols, 30.f);
  d(cv::Rect(c0, 10, c1 - c0 + 1, 30)).setTo(10.f);
  s.set(Layer{std::string(layer::kDistance), d, {}});
  return s;
}

LaserExtentParams on() {
  LaserExtentParams p;
  p.enabled = true;  // tolerance 1 m, share 0.5, max move 0.3, margin 0.05
  return p;
}

}  // namespace

// Box x 25..55 (w 30), y 10..40 on an object over columns 20..59: band rows floor(10 + 0.35 * 30)
// = 20 .. floor(10 + 0.85 * 30) = 35, core columns 32..47 -> d0 = 10; walks from column 40 reach
// at most 9 columns (0.3 x 30) beyond each edge (16 and 64) and end at 20 and 59 (19 and 60 are
// background). Left = 20 - 0.05 x 30 = 18.5, right = 59 + 1 + 1.5 = 61.5.
TEST(LaserExtent, NarrowBoxWidensToTheObjectPlusMargin) {
  const LayerStack s = scene(100, 50, 100, 50, 20, 59);
  EXPECT_EQ(laserExtentBox(Box{25, 10, 30, 30}, s, on()), (Box{18.5, 10, 43, 30}));
  LaserExtentParams off = on();
  off.enabled = false;
  EXPECT_EQ(laserExtentBox(Box{25, 10, 30, 30}, s, off), (Box{25, 10, 30, 30}));
}

// The same scene with a laser layer of half the reference resolution: the box in reference pixels
// is twice as large, the result too (18.5 / 0.5 = 37, 61.5 / 0.5 = 123).
TEST(LaserExtent, LaserGridOfItsOwnResolution) {
  const LayerStack s = scene(200, 100, 100, 50, 20, 59);
  EXPECT_EQ(laserExtentBox(Box{50, 20, 60, 60}, s, on()), (Box{37, 20, 86, 60}));
}

// A side seen at a slant: columns 20..29 recede by 0.5 m per column (12.5 m at column 25, 15 m at
// 20). Each column is within 1 m of the previous one's median, so the walk follows it to column 20
// (a fixed 1 m around d0 = 10 would stop at column 28).
TEST(LaserExtent, SlantedSideContinuesTheObject) {
  LayerStack s = scene(100, 50, 100, 50, 20, 59);
  cv::Mat1f d = s.find(layer::kDistance)->data;
  for (int c = 20; c < 30; ++c) d(cv::Rect(c, 10, 1, 30)).setTo(10.f + 0.5f * float(30 - c));
  EXPECT_EQ(laserExtentBox(Box{25, 10, 30, 30}, s, on()), (Box{18.5, 10, 43, 30}));
}

// Edges only move outwards; a walk that reaches its limit (the cluster goes on: a wall from column
// 0) leaves that edge where it was.
TEST(LaserExtent, WideBoxesAndEndlessClustersKeepTheirEdges) {
  const LayerStack s = scene(100, 50, 100, 50, 20, 59);
  EXPECT_EQ(laserExtentBox(Box{15, 10, 50, 30}, s, on()), (Box{15, 10, 50, 30}));
  const LayerStack wall = scene(100, 50, 100, 50, 0, 59);
  EXPECT_EQ(laserExtentBox(Box{25, 10, 30, 30}, wall, on()), (Box{25, 10, 36.5, 30}));  // right 61.5
}

// No laser on the box: no distance layer, every cell masked out, or the middle column not on the
// object's median distance -> unchanged; detections get box and unitBox refined together.
TEST(LaserExtent, WithoutLaserTheBoxStays) {
  const Box b{25, 10, 30, 30};
  LayerStack camera(100, 50);
  camera.set(Layer{"intensity", cv::Mat(50, 100, CV_8U, cv::Scalar(7)), {}});
  EXPECT_EQ(laserExtentBox(b, camera, on()), b);
  LayerStack masked = scene(100, 50, 100, 50, 20, 59);
  masked.find(layer::kDistance)->valid = cv::Mat(50, 100, CV_8U, cv::Scalar(0));
  EXPECT_EQ(laserExtentBox(b, masked, on()), b);
  LayerStack hole = scene(100, 50, 100, 50, 20, 59);
  hole.find(layer::kDistance)->data(cv::Rect(38, 0, 5, 50)).setTo(30.f);  // a gap at the centre column 40
  EXPECT_EQ(laserExtentBox(b, hole, on()), b);

  const LayerStack s = scene(100, 50, 100, 50, 20, 59);
  std::vector<Detection> dets(1);
  dets[0].box = b;
  refineToLaserExtent(dets, s, on());
  EXPECT_EQ(dets[0].box, (Box{18.5, 10, 43, 30}));
  EXPECT_NEAR(dets[0].unitBox.x, 0.185, 1e-12);
  EXPECT_NEAR(dets[0].unitBox.y, 0.2, 1e-12);
  EXPECT_NEAR(dets[0].unitBox.w, 0.43, 1e-12);
  EXPECT_NEAR(dets[0].unitBox.h, 0.6, 1e-12);
}
