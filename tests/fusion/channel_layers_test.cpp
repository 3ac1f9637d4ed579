// Channels beyond the paper (fusion/channel_layers.h) on hand-made inputs with known answers.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <numbers>
#include <opencv2/core.hpp>
#include <random>

#include "fusedet/fusion/camera_layers.h"
#include "fusedet/fusion/channel_layers.h"
#include "fusedet/core/hue_distance.h"

using namespace fusedet;
using namespace fusedet::fusion;

namespace {
LayerStack intensityStack(const cv::Mat& grey) {
  LayerStack s;
  s.setReferenceSize(grey.cols, grey.rows);
  s.set(Layer{"intensity", grey, {}});
  return s;
}
}  // namespace

TEST(GradientChannels, VerticalEdgeIsOrientationZeroHorizontalEdgeIsNinetyDegrees) {
  // Left half 0, right half 100: at the two columns next to the step, central differences give
  // gx = 100, gy = 0 -> magnitude 100 / sqrt(2) = 70.7 -> 71, orientation 0 -> bin 0.
  cv::Mat v(8, 8, CV_8UC1, cv::Scalar(0));
  v(cv::Rect(4, 0, 4, 8)).setTo(100);
  ChannelConfig full;
  full.gradientScale = 1.0;
  LayerStack s = intensityStack(v);
  addGradientChannels(s, full);
  EXPECT_EQ(s.at("grad_mag").data.at<std::uint8_t>(3, 3), 71);
  EXPECT_EQ(s.at("grad_mag").data.at<std::uint8_t>(3, 4), 71);
  EXPECT_EQ(s.at("grad_mag").data.at<std::uint8_t>(3, 1), 0);
  EXPECT_EQ(s.at("grad_0").data.at<std::uint8_t>(3, 3), 71);
  for (int k = 1; k < 6; ++k) EXPECT_EQ(s.at("grad_" + std::to_string(k)).data.at<std::uint8_t>(3, 3), 0) << k;

  // Top 0, bottom 100: gy = 100 -> orientation 90 deg -> bin 3 (90 / 30).
  cv::Mat h(8, 8, CV_8UC1, cv::Scalar(0));
  h(cv::Rect(0, 4, 8, 4)).setTo(100);
  LayerStack t = intensityStack(h);
  addGradientChannels(t, full);
  EXPECT_EQ(t.at("grad_3").data.at<std::uint8_t>(4, 2), 71);
  EXPECT_EQ(t.at("grad_0").data.at<std::uint8_t>(4, 2), 0);

  // Default: half resolution.
  LayerStack u = intensityStack(cv::Mat(10, 20, CV_8UC1, cv::Scalar(7)));
  addGradientChannels(u);
  EXPECT_EQ(u.at("grad_mag").width(), 10);
  EXPECT_EQ(u.at("grad_mag").height(), 5);
  EXPECT_EQ(cv::countNonZero(u.at("grad_mag").data), 0);  // constant image: no gradient
  LayerStack none;
  none.setReferenceSize(4, 4);
  EXPECT_THROW(addGradientChannels(none), std::out_of_range);
}

TEST(GroundPlane, RecoversAFlatGroundUnderBoxes) {
  // Ground 1.6 m below the camera (camera y down: y = 1.6), tilted by 2 degrees about x, plus
  // a box's front (a vertical wall) that must not win.
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.02);
  const double tilt = 2.0 * std::numbers::pi / 180;
  std::vector<Eigen::Vector3d> pts;
  for (int i = 0; i < 3000; ++i) {
    const double x = -10 + 20.0 * (i % 60) / 60, z = 3 + 40.0 * (i / 60) / 50;
    pts.emplace_back(x, 1.6 + z * std::tan(tilt) + noise(rng), z);
  }
  for (int i = 0; i < 1500; ++i) pts.emplace_back(-2 + 4.0 * (i % 40) / 40, 1.6 - 2.0 * (i / 40) / 38, 12 + noise(rng));
  const auto plane = fitGroundPlane(pts);
  ASSERT_TRUE(plane.has_value());
  // Expected normal: up (0, -1, 0) rotated by the tilt: (0, -cos, sin).
  EXPECT_NEAR(plane->normal.y(), -std::cos(tilt), 2e-3);
  EXPECT_NEAR(plane->normal.z(), std::sin(tilt), 5e-3);
  EXPECT_NEAR(plane->normal.dot(Eigen::Vector3d(0, 1.6, 0)) + plane->offset, 0.0, 0.02);  // on the ground
  // A point 1 m above the ground at z = 10.
  const Eigen::Vector3d above(0, 1.6 + 10 * std::tan(tilt) - 1.0 / std::cos(tilt), 10);
  EXPECT_NEAR(plane->normal.dot(above) + plane->offset, 1.0, 0.03);
  EXPECT_FALSE(fitGroundPlane({Eigen::Vector3d(0, 1, 1), Eigen::Vector3d(1, 1, 1)}).has_value());
}

TEST(LaserChannels, HeightOfAFlatGroundIsZeroAndDistanceGradientFollowsTheRange) {
  // A distance layer rendered from a ground plane 1.5 m below a pinhole camera: every measured
  // cell lies on the ground, so height ~ 0; cells of the top half see no ground (invalid).
  const int W = 200, H = 100;
  Eigen::Matrix3d K;
  K << 100, 0, 100, 0, 100, 50, 0, 0, 1;
  cv::Mat dist(H / 2, W / 2, CV_32FC1, cv::Scalar(0)), valid(H / 2, W / 2, CV_8UC1, cv::Scalar(0));
  for (int r = 0; r < dist.rows; ++r)
    for (int c = 0; c < dist.cols; ++c) {
      const Eigen::Vector3d ray = K.inverse() * Eigen::Vector3d((c + 0.5) * 2, (r + 0.5) * 2, 1);
      if (ray.y() <= 0.05) continue;  // above the horizon (or too far)
      const double t = 1.5 / ray.y();   // ray * t hits y = 1.5
      dist.at<float>(r, c) = static_cast<float>((ray * t).norm());
      valid.at<std::uint8_t>(r, c) = 255;
    }
  LayerStack s;
  s.setReferenceSize(W, H);
  s.set(Layer{"distance", dist, valid});
  addLaserChannels(s, K);
  const Layer& height = s.at("height");
  ASSERT_EQ(height.width(), W / 2);
  double worst = 0;
  for (int r = 0; r < H / 2; ++r)
    for (int c = 0; c < W / 2; ++c)
      if (valid.at<std::uint8_t>(r, c)) worst = std::max(worst, std::abs(double(height.data.at<float>(r, c))));
  EXPECT_LT(worst, 0.01);
  EXPECT_EQ(cv::countNonZero(height.valid), cv::countNonZero(valid));
  // Depth gradient: along a column range falls towards the bottom; central difference of two
  // neighbours' ranges, so a cell's value equals |d(r+1) - d(r-1)| / 2 there.
  const int c = 50, r = 40;
  const double expect = std::abs(dist.at<float>(r + 1, c) - dist.at<float>(r - 1, c)) / 2;
  const double dx = (dist.at<float>(r, c + 1) - dist.at<float>(r, c - 1)) / 2.0;
  EXPECT_NEAR(s.at("distance_grad").data.at<float>(r, c), std::hypot(expect, dx), 1e-4);
}

TEST(HueMask, GreyAndDarkPixelsCarryNoHue) {
  cv::Mat bgr(1, 4, CV_8UC3);
  bgr.at<cv::Vec3b>(0, 0) = cv::Vec3b(120, 120, 120);  // grey: saturation 0
  bgr.at<cv::Vec3b>(0, 1) = cv::Vec3b(0, 0, 30);       // dark red: value 30 < 40
  bgr.at<cv::Vec3b>(0, 2) = cv::Vec3b(200, 190, 210);  // washed out: saturation 20/210 = 0.095
  bgr.at<cv::Vec3b>(0, 3) = cv::Vec3b(40, 60, 200);    // saturated red-orange
  const cv::Mat m = hueValidMask(bgr);
  EXPECT_EQ(m.at<std::uint8_t>(0, 0), 0);
  EXPECT_EQ(m.at<std::uint8_t>(0, 1), 0);
  EXPECT_EQ(m.at<std::uint8_t>(0, 2), 0);
  EXPECT_EQ(m.at<std::uint8_t>(0, 3), 255);
  LayerStack s;
  addCameraLayers(s, bgr);
  EXPECT_EQ(cv::countNonZero(s.at("hue").valid), 1);
  // The masked grey pixel is the neutral 90 degrees from any reference hue.
  EXPECT_FLOAT_EQ(hueDistanceLayer(s.at("hue").data, s.at("hue").valid, 215).at<float>(0, 0), 90.f);
}
