// SPDX-License-Identifier: Apache-2.0
// Camera layers (fusedet/fusion/camera_layers.h) on hand-made pixels with known answers: the hue mask, the image back.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <stdexcept>
#include <string>

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

TEST(CameraImage, IsTheImageTheLayersCameFromAndNamesWhatIsMissing) {
  cv::Mat bgr(3, 5, CV_8UC3);
  cv::randu(bgr, cv::Scalar::all(0), cv::Scalar::all(256));
  LayerStack s;
  addCameraLayers(s, bgr);
  ASSERT_TRUE(hasCameraImage(s));
  cv::Mat back = cameraImage(s);
  ASSERT_EQ(back.type(), CV_8UC3);
  EXPECT_EQ(cv::norm(back, bgr, cv::NORM_INF), 0.0);
  back.setTo(cv::Scalar::all(7));  // its own pixels: the layers stay as they were
  EXPECT_EQ(cv::norm(cameraImage(s), bgr, cv::NORM_INF), 0.0);

  LayerStack noGreen;
  noGreen.set(s.at("red"));
  noGreen.set(s.at("blue"));
  EXPECT_FALSE(hasCameraImage(noGreen));
  try {
    cameraImage(noGreen);
    FAIL() << "no green layer, yet an image";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'green'"), std::string::npos) << e.what();
  }
  LayerStack floatRed = s;
  cv::Mat redF;
  s.at("red").data.convertTo(redF, CV_32F);
  floatRed.set({"red", redF, {}});
  EXPECT_FALSE(hasCameraImage(floatRed));
  LayerStack smallBlue = s;
  smallBlue.set({"blue", cv::Mat(2, 5, CV_8UC1, cv::Scalar(1)), {}});
  EXPECT_FALSE(hasCameraImage(smallBlue));
  EXPECT_THROW(cameraImage(smallBlue), std::invalid_argument);
}
