// SPDX-License-Identifier: Apache-2.0
// Parts of synth-log: ray casting into a point cloud, YUYV encoding (checked
// through the independent OpenCV decoder decodeCameraFrame uses), the procedural scene.

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <random>

#include "fusedet/fusion/frame_decode.h"
#include "fusedet/fusion/synthesis/frame_encode.h"
#include "fusedet/fusion/synthesis/point_ray_caster.h"
#include "fusedet/fusion/synthesis/synth_scene.h"

using namespace fusedet;
using namespace fusedet::fusion;

TEST(PointRayCaster, FirstSurfaceWithinTolerance) {
  Sweep cloud;
  // a wall at x = 10 (grid of points 5 cm apart) and a post in front of it at x = 5, y = 0
  for (double y = -2; y <= 2; y += 0.05)
    for (double z = -1; z <= 1; z += 0.05) cloud.points.push_back({10.f, float(y), float(z), 0.5f, 0});
  cloud.points.push_back({5.f, 0.f, 0.f, 0.9f, 0});
  const PointRayCaster c(cloud, 0.4 * M_PI / 180, 0.1, 2.0);
  auto hit = c.cast(Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 0, 0));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 5.0, 1e-6);  // the post hides the wall
  EXPECT_FLOAT_EQ(hit->remission, 0.9f);
  const Eigen::Vector3d d = Eigen::Vector3d(10, 1.02, 0.3).normalized();
  hit = c.cast(Eigen::Vector3d::Zero(), d);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10 / d.x(), 0.03);  // range along the ray to the nearest wall point
  // from an origin 5 cm above: the geometry follows the ray origin
  hit = c.cast(Eigen::Vector3d(0, 0.5, 0.05), Eigen::Vector3d(1, 0, 0));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 10.0, 1e-6);
  EXPECT_FALSE(c.cast(Eigen::Vector3d::Zero(), Eigen::Vector3d(-1, 0, 0)));  // nothing behind
  EXPECT_FALSE(c.cast(Eigen::Vector3d::Zero(), Eigen::Vector3d(10, 2.3, 0).normalized()));  // past the wall's edge
}

TEST(FrameEncode, YuyvRoundTripThroughOpenCv) {
  cv::Mat bgr(40, 64, CV_8UC3);
  std::mt19937 rng(3);
  for (int y = 0; y < bgr.rows; ++y)
    for (int x = 0; x < bgr.cols; ++x)  // smooth colours (chroma is shared by pixel pairs)
      bgr.at<cv::Vec3b>(y, x) = cv::Vec3b(static_cast<std::uint8_t>(4 * x), static_cast<std::uint8_t>(6 * y),
                                          static_cast<std::uint8_t>(128 + (x / 2 + y) % 64));
  const drivers::CameraFrame f = encodeYuyvFrame(bgr);
  EXPECT_EQ(f.bytes.size(), 40u * 64 * 2);
  auto back = decodeCameraFrame(f);
  ASSERT_TRUE(back) << back.error().message();
  cv::Mat diff;
  cv::absdiff(*back, bgr, diff);
  double maxDiff = 0;
  cv::minMaxLoc(diff.reshape(1), nullptr, &maxDiff);
  EXPECT_LE(maxDiff, 6.0);
  EXPECT_LE(cv::mean(diff)[0], 2.0);
  EXPECT_THROW(encodeYuyvFrame(cv::Mat(4, 5, CV_8UC3)), std::invalid_argument);
}

TEST(ProceduralScene, KnownGeometry) {
  const ProceduralScene s;
  // straight down from 1 m above the origin: ground at 2.73 m
  auto hit = s.cast(Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(0, 0, -1));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 1 - ProceduralScene::kGroundZ, 1e-9);
  // ahead at 1 m height on y = 3: the left box's face at x = 18
  hit = s.cast(Eigen::Vector3d(0, 3, ProceduralScene::kGroundZ + 1), Eigen::Vector3d(1, 0, 0));
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->range, 18.0, 1e-9);
  EXPECT_FALSE(s.cast(Eigen::Vector3d::Zero(), Eigen::Vector3d(0, 0, 1)));  // sky
  CameraModel cam;
  cam.width = 64;
  cam.height = 32;
  cam.K << 40, 0, 32, 0, 40, 16, 0, 0, 1;
  Eigen::Isometry3d baseToCam = Eigen::Isometry3d::Identity();
  baseToCam.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const cv::Mat img = s.render(cam, baseToCam);
  EXPECT_EQ(img.at<cv::Vec3b>(0, 32), cv::Vec3b(235, 206, 135));  // top centre: sky
  EXPECT_NE(img.at<cv::Vec3b>(31, 32), cv::Vec3b(235, 206, 135));  // bottom centre: ground
}
