// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/layer_stack.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>

using fusedet::Box;
using fusedet::Layer;
using fusedet::LayerStack;

TEST(LayerStack, AddFindReplace) {
  LayerStack s(640, 480);
  s.set(Layer{"intensity", cv::Mat(480, 640, CV_8UC1, cv::Scalar(7)), {}});
  s.set(Layer{"distance", cv::Mat(240, 320, CV_32FC1, cv::Scalar(2.5f)), cv::Mat(240, 320, CV_8UC1, cv::Scalar(1))});
  ASSERT_EQ(s.size(), 2u);
  EXPECT_TRUE(s.has("distance"));
  EXPECT_FALSE(s.has("remission"));
  EXPECT_TRUE(s.at("distance").hasMask());
  s.set(Layer{"intensity", cv::Mat(480, 640, CV_8UC1, cv::Scalar(9)), {}});
  EXPECT_EQ(s.size(), 2u);
  EXPECT_EQ(s.at("intensity").data.at<std::uint8_t>(0, 0), 9);
  EXPECT_EQ(s.names(), (std::vector<std::string>{"intensity", "distance"}));
}

TEST(LayerStack, RejectsBadLayers) {
  LayerStack s(4, 4);
  EXPECT_THROW(s.set(Layer{"", cv::Mat(4, 4, CV_8UC1), {}}), std::invalid_argument);
  EXPECT_THROW(s.set(Layer{"rgb", cv::Mat(4, 4, CV_8UC3), {}}), std::invalid_argument);
  EXPECT_THROW(s.set(Layer{"d", cv::Mat(4, 4, CV_64FC1), {}}), std::invalid_argument);
  EXPECT_THROW(s.set(Layer{"m", cv::Mat(4, 4, CV_8UC1), cv::Mat(2, 2, CV_8UC1)}), std::invalid_argument);
  try {
    (void)s.at("hue");
    FAIL();
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("hue"), std::string::npos);
  }
}

TEST(LayerStack, UnitSquareMapsToEachLayersGrid) {
  LayerStack s(1242, 375);
  s.set(Layer{"intensity", cv::Mat(375, 1242, CV_8UC1), {}});
  s.set(Layer{"distance", cv::Mat(187, 621, CV_32FC1), {}});
  const Box px{621, 75, 124.2, 150};
  const Box unit = s.toUnit(px);
  EXPECT_DOUBLE_EQ(unit.x, 0.5);
  EXPECT_DOUBLE_EQ(unit.y, 0.2);
  EXPECT_DOUBLE_EQ(unit.w, 0.1);
  const Box back = s.toPixels(unit);
  EXPECT_NEAR(back.w, px.w, 1e-9);
  const Box inDistance = LayerStack::toLayerPixels(s.at("distance"), unit);
  EXPECT_DOUBLE_EQ(inDistance.x, 310.5);
  EXPECT_DOUBLE_EQ(inDistance.h, 0.4 * 187);
}
