// SPDX-License-Identifier: Apache-2.0
// The hue layer's mask (fusedet/fusion/camera_layers.h) on hand-made pixels with known answers.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include "fusedet/core/hue_distance.h"
#include "fusedet/fusion/camera_layers.h"

using namespace fusedet;
using namespace fusedet::fusion;

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
