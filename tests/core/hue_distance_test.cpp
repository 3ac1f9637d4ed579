#include "fusedet/core/hue_distance.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

TEST(HueDistance, WrapsAroundZero) {
  EXPECT_DOUBLE_EQ(fusedet::hueDistanceDeg(350, 10), 20);
  EXPECT_DOUBLE_EQ(fusedet::hueDistanceDeg(10, 350), 20);
  EXPECT_DOUBLE_EQ(fusedet::hueDistanceDeg(0, 180), 180);
  EXPECT_DOUBLE_EQ(fusedet::hueDistanceDeg(90, 90), 0);
  EXPECT_DOUBLE_EQ(fusedet::hueDistanceDeg(-30, 390), 60);  // -30 = 330, 390 = 30
}

TEST(HueDistance, LayerMatchesScalarAcrossTheWrap) {
  cv::Mat hue(1, 6, CV_32FC1);
  const float values[] = {0.f, 5.f, 185.f, 355.f, 359.5f, 90.f};
  for (int i = 0; i < 6; ++i) hue.at<float>(0, i) = values[i];
  const cv::Mat d = fusedet::hueDistanceLayer(hue, 350.0);
  for (int i = 0; i < 6; ++i)
    EXPECT_NEAR(d.at<float>(0, i), fusedet::hueDistanceDeg(values[i], 350.0), 1e-4) << values[i];
  EXPECT_NEAR(d.at<float>(0, 0), 10.f, 1e-4);   // 0 vs 350 across the wrap
  EXPECT_NEAR(d.at<float>(0, 2), 165.f, 1e-4);  // 185 vs 350
  EXPECT_THROW((void)fusedet::hueDistanceLayer(cv::Mat(2, 2, CV_8UC1), 0), std::invalid_argument);
}

TEST(HueDistance, PixelsWithoutHueAreNeutral) {
  cv::Mat hue(1, 3, CV_32FC1);
  hue.at<float>(0, 0) = 0.f;    // "red" only because the pixel was grey
  hue.at<float>(0, 1) = 10.f;
  hue.at<float>(0, 2) = 200.f;
  cv::Mat valid(1, 3, CV_8UC1, cv::Scalar(255));
  valid.at<unsigned char>(0, 0) = 0;
  const cv::Mat d = fusedet::hueDistanceLayer(hue, valid, 0.0);
  EXPECT_EQ(d.at<float>(0, 0), 90.f);  // not 0: a grey pixel is not the class's red
  EXPECT_NEAR(d.at<float>(0, 1), 10.f, 1e-4);
  EXPECT_NEAR(d.at<float>(0, 2), 160.f, 1e-4);
  const cv::Mat all = fusedet::hueDistanceLayer(hue, cv::Mat(), 0.0);
  EXPECT_EQ(all.at<float>(0, 0), 0.f);
  EXPECT_THROW((void)fusedet::hueDistanceLayer(hue, cv::Mat(2, 2, CV_8UC1), 0.0), std::invalid_argument);
}
