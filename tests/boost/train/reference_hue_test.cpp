// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/reference_hue.h"

#include <gtest/gtest.h>

using namespace fusedet;
using namespace fusedet::boosting;

TEST(ReferenceHue, ArgmaxOfSmoothedTenDegreeBins) {
  HueHistogram h;
  for (int i = 0; i < 10; ++i) h.addHue(123);  // bin 12 (120-130)
  for (int i = 0; i < 6; ++i) h.addHue(200);   // bin 20
  for (int i = 0; i < 6; ++i) h.addHue(215);   // bin 21: 20 and 21 smooth to 4.5 each...
  for (int i = 0; i < 6; ++i) h.addHue(225);   // ...bin 22: smoothed bin 21 = (6 + 12 + 6) / 4 = 6
  EXPECT_DOUBLE_EQ(h.smoothed()[12], 5.0);
  EXPECT_DOUBLE_EQ(h.smoothed()[21], 6.0);
  EXPECT_DOUBLE_EQ(h.referenceHue(), 215.0);
}

TEST(ReferenceHue, WrapsAroundZero) {
  HueHistogram h;
  for (int i = 0; i < 5; ++i) h.addHue(355);
  for (int i = 0; i < 5; ++i) h.addHue(-5);  // = 355
  for (int i = 0; i < 4; ++i) h.addHue(2);   // bin 0
  for (int i = 0; i < 7; ++i) h.addHue(90);
  EXPECT_DOUBLE_EQ(h.bins()[35], 10.0);
  // bin 35 smoothed: (0 + 20 + 4) / 4 = 6 > bin 9: 7 * 2 / 4 = 3.5
  EXPECT_DOUBLE_EQ(h.referenceHue(), 355.0);
  EXPECT_THROW(HueHistogram().referenceHue(), std::runtime_error);
}

TEST(ReferenceHue, ReadsTheHueLayerInsideABoxAtItsOwnResolution) {
  LayerStack s(200, 100);
  cv::Mat hue(50, 100, CV_32F, cv::Scalar(30.f));  // half resolution
  hue(cv::Rect(50, 10, 20, 20)).setTo(250.f);       // reference pixels x 100..140, y 20..60
  s.set(Layer{"hue", hue, {}});
  HueHistogram h;
  h.add(s, Box{100, 20, 40, 40});
  EXPECT_DOUBLE_EQ(h.total(), 400.0);
  EXPECT_DOUBLE_EQ(h.referenceHue(), 255.0);
  LayerStack noHue(10, 10);
  EXPECT_THROW(h.add(noHue, Box{0, 0, 5, 5}), std::out_of_range);
}

TEST(ReferenceHue, DistinctiveHueIsWhatTheClassHasAndTheBackgroundLacks) {
  // Class pixels: 60 % bluish grey (215, like the whole street), 40 % red (5). The mode is 215;
  // the distinctive hue is red, which the background seldom has.
  HueHistogram cls, bg;
  cls.addHue(215, 60);
  cls.addHue(5, 40);
  bg.addHue(215, 900);
  bg.addHue(5, 10);
  bg.addHue(100, 90);
  EXPECT_DOUBLE_EQ(cls.referenceHue(), 215.0);
  EXPECT_DOUBLE_EQ(cls.distinctiveHue(bg), 5.0);
  // A bin with less than minShare of the class never wins, however rare in the background.
  cls.addHue(300, 1);
  EXPECT_DOUBLE_EQ(cls.distinctiveHue(bg), 5.0);
  EXPECT_THROW((void)cls.distinctiveHue(HueHistogram()), std::runtime_error);
  // addImage skips pixels the mask marks as hue-less.
  LayerStack s(4, 4);
  cv::Mat valid(4, 4, CV_8U, cv::Scalar(0));
  valid.at<std::uint8_t>(0, 0) = 255;
  s.set(Layer{"hue", cv::Mat(4, 4, CV_32F, cv::Scalar(120.f)), valid});
  HueHistogram img;
  img.addImage(s, 1);
  EXPECT_DOUBLE_EQ(img.total(), 1.0);
}
