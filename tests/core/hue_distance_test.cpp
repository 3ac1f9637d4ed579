// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/hue_distance.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <vector>

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

// The row functions (vectorised) give exactly the per-pixel rule "d = |h - ref|; d > 180 ? 360 - d
// : d" (masked pixels kNoHueDistance), bit for bit: dense hues around the fold at 180, the wrap,
// NaN, and row lengths that leave vector remainders; with and without a mask.
TEST(HueDistance, RowsEqualThePerPixelRuleBitForBit) {
  std::vector<float> hues;
  for (int i = 0; i <= 3600; ++i) hues.push_back(0.1f * float(i));  // 0 .. 360 in 0.1 steps (float rounding)
  for (float h : {179.99998f, 180.f, 180.00002f, 0.f, 359.99997f, 1e-30f}) hues.push_back(h);
  hues.push_back(std::numeric_limits<float>::quiet_NaN());
  std::vector<unsigned char> valid(hues.size());
  for (std::size_t i = 0; i < valid.size(); ++i) valid[i] = (i * 7 % 5) ? 255 : 0;
  for (double reference : {0.0, 10.0, 179.5, 180.0, 350.0, -30.0, 725.25}) {
    const auto ref = static_cast<float>(std::fmod(std::fmod(reference, 360.0) + 360.0, 360.0));
    for (int n : {1, 3, 7, 8, 9, 17, static_cast<int>(hues.size())}) {
      std::vector<float> plain(static_cast<std::size_t>(n)), masked(static_cast<std::size_t>(n));
      fusedet::hueDistanceRow(hues.data(), plain.data(), n, reference);
      fusedet::hueDistanceRow(hues.data(), valid.data(), masked.data(), n, reference);
      for (int x = 0; x < n; ++x) {
        const float d = std::fabs(hues[static_cast<std::size_t>(x)] - ref);
        const float expected = d > 180.f ? 360.f - d : d;
        const float expectedMasked = valid[static_cast<std::size_t>(x)] ? expected : fusedet::kNoHueDistance;
        std::uint32_t a = 0, b = 0, c = 0, e = 0;
        std::memcpy(&a, &plain[static_cast<std::size_t>(x)], 4);
        std::memcpy(&b, &expected, 4);
        std::memcpy(&c, &masked[static_cast<std::size_t>(x)], 4);
        std::memcpy(&e, &expectedMasked, 4);
        ASSERT_EQ(a, b) << "hue " << hues[static_cast<std::size_t>(x)] << " reference " << reference;
        ASSERT_EQ(c, e) << "hue " << hues[static_cast<std::size_t>(x)] << " reference " << reference;
      }
    }
  }
}
