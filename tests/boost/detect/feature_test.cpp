// SPDX-License-Identifier: Apache-2.0
// Features a-j against a pixel-by-pixel computation of mean(black) - mean(white), integral images
// against brute-force sums, and layers of different resolutions.

#include "fusedet/boost/feature.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "fusedet/core/hue_distance.h"

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

cv::Mat randomImage(int w, int h, int type, unsigned seed) {
  cv::Mat m(h, w, type);
  cv::RNG rng(seed);
  if (type == CV_32F) rng.fill(m, cv::RNG::UNIFORM, -50.0, 300.0);
  else if (type == CV_16U) rng.fill(m, cv::RNG::UNIFORM, 0, 65536);
  else rng.fill(m, cv::RNG::UNIFORM, 0, 256);
  return m;
}

double bruteSum(const cv::Mat& m, int x0, int y0, int x1, int y1) {
  double s = 0;
  cv::Mat d;
  m.convertTo(d, CV_64F);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) s += d.at<double>(y, x);
  return s;
}

// Black membership of pixel (u, v) of an n x n feature whose cells are exact thirds / halves.
bool isBlack(FeatureType t, int u, int v, int n) {
  const bool left = u < n / 2, top = v < n / 2;
  const bool midX = u >= n / 3 && u < 2 * n / 3, midY = v >= n / 3 && v < 2 * n / 3;
  switch (t) {
    case FeatureType::kEdgeHorizontal: return left;
    case FeatureType::kEdgeVertical: return top;
    case FeatureType::kLineHorizontal: return midX;
    case FeatureType::kLineVertical: return midY;
    case FeatureType::kChecker: return left == top;
    case FeatureType::kCenterSurround: return midX && midY;
    case FeatureType::kCornerTopLeft: return left && top;
    case FeatureType::kCornerTopRight: return !left && top;
    case FeatureType::kCornerBottomLeft: return left && !top;
    case FeatureType::kCornerBottomRight: return !left && !top;
  }
  return false;
}

LayerStack stackOf(const cv::Mat& m, const std::string& name = "intensity") {
  LayerStack s(m.cols, m.rows);
  s.set(Layer{name, m, {}});
  return s;
}

}  // namespace

TEST(IntegralStack, RectSumsEqualBruteForceForEveryDepth) {
  for (int type : {CV_8U, CV_16U, CV_32F}) {
    const cv::Mat m = randomImage(37, 23, type, 7 + type);
    const LayerIntegral li = integrateLayer("x", m);
    ASSERT_EQ(li.sum.size(), 38u * 24u);
    std::mt19937 rng(3);
    for (int i = 0; i < 200; ++i) {
      int x0 = int(rng() % 37), x1 = int(rng() % 38), y0 = int(rng() % 23), y1 = int(rng() % 24);
      if (x0 > x1) std::swap(x0, x1);
      if (y0 > y1) std::swap(y0, y1);
      const double expect = bruteSum(m, x0, y0, x1, y1);
      if (type == CV_32F) EXPECT_NEAR(li.rectSum(x0, y0, x1, y1), expect, 1e-6 * (1 + std::abs(expect)));
      else EXPECT_EQ(li.rectSum(x0, y0, x1, y1), expect);  // exact for integer layers
    }
  }
}

TEST(IntegralStack, SixteenBitSumsAreExactAtFourK) {
  cv::Mat m(2160, 3840, CV_16U, cv::Scalar(65535));
  const LayerIntegral li = integrateLayer("distance", m);
  EXPECT_EQ(li.rectSum(0, 0, 3840, 2160), 65535.0 * 3840 * 2160);
  EXPECT_EQ(li.rectSum(1, 1, 3840, 2160) - li.rectSum(2, 1, 3840, 2160), 65535.0 * 2159);
}

TEST(IntegralStack, DerivesHueDistanceFromHueWithTheReferenceHue) {
  cv::Mat hue = randomImage(20, 10, CV_32F, 1);
  hue = cv::abs(hue);
  LayerStack s = stackOf(hue, "hue");
  const std::vector<std::string> names{"hue_distance"};
  EXPECT_THROW(IntegralStack(s, names), std::invalid_argument);
  const IntegralStack in(s, names, 40.0);
  const cv::Mat expected = hueDistanceLayer(hue, 40.0);
  EXPECT_NEAR(in.layer(0).rectSum(0, 0, 20, 10), bruteSum(expected, 0, 0, 20, 10), 1e-3);
  const std::vector<std::string> missing{"distance"};
  EXPECT_THROW(IntegralStack(s, missing), std::out_of_range);
}

TEST(Feature, EveryTypeIsMeanBlackMinusMeanWhitePixelByPixel) {
  const int n = 12;  // divisible by 2 and 3: cells are exact
  const cv::Mat m = randomImage(40, 30, CV_8U, 11);
  const LayerStack s = stackOf(m);
  const std::vector<std::string> names{"intensity"};
  const IntegralStack in(s, names);
  cv::Mat d;
  m.convertTo(d, CV_64F);
  for (int t = 0; t < int(kFeatureTypeCount); ++t) {
    const auto type = static_cast<FeatureType>(t);
    // Window 24x24 at (5, 3); feature covers window pixels [6, 18) x [12, 24).
    const Feature f{type, Box{0.25, 0.5, 0.5, 0.5}, 0};
    double sb = 0, sw = 0;
    int nb = 0, nw = 0;
    for (int v = 0; v < n; ++v)
      for (int u = 0; u < n; ++u) {
        const double px = d.at<double>(3 + 12 + v, 5 + 6 + u);
        if (isBlack(type, u, v, n)) sb += px, ++nb;
        else sw += px, ++nw;
      }
    const double expect = sb / nb - sw / nw;
    EXPECT_NEAR(featureValue(in, f, Box{5, 3, 24, 24}), expect, 1e-4) << toLetter(type);
  }
}

TEST(Feature, ZeroOnConstantInputAtAnySizeAndResolution) {
  const cv::Mat m(50, 80, CV_32F, cv::Scalar(3.5));
  const cv::Mat small(13, 20, CV_32F, cv::Scalar(3.5));
  LayerStack s(80, 50);
  s.set(Layer{"a", m, {}});
  s.set(Layer{"b", small, {}});
  const std::vector<std::string> names{"a", "b"};
  const IntegralStack in(s, names);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 300; ++i) {
    const double x = u(rng) * 0.8, y = u(rng) * 0.8;
    const Feature f{static_cast<FeatureType>(i % 10), Box{x, y, (1 - x) * u(rng) + 1e-3, (1 - y) * u(rng) + 1e-3}, i % 2};
    const Box win{double(rng() % 40), double(rng() % 20), 10.0 + double(rng() % 30), 10.0 + double(rng() % 25)};
    EXPECT_FLOAT_EQ(featureValue(in, f, win), 0.f) << describe(f);
  }
}

TEST(Feature, LayersOfLowerResolutionGiveTheSameValueOnAlignedWindows) {
  // A 2x2-block image and its half-resolution version hold the same picture.
  const cv::Mat lowRes = randomImage(30, 20, CV_8U, 9);
  cv::Mat full;
  cv::resize(lowRes, full, cv::Size(60, 40), 0, 0, cv::INTER_NEAREST);
  LayerStack s(60, 40);
  s.set(Layer{"full", full, {}});
  s.set(Layer{"half", lowRes, {}});
  const std::vector<std::string> names{"full", "half"};
  const IntegralStack in(s, names);
  for (int t = 0; t < int(kFeatureTypeCount); ++t) {
    const auto type = static_cast<FeatureType>(t);
    const Box unit{1.0 / 6, 1.0 / 6, 4.0 / 6, 4.0 / 6};  // 24x24 window: 4..20 = 16 px, 8 on the half layer... cells
    const Box win{10, 6, 36, 36};                        // 18x18 on the half layer, feature 12x12
    const float a = featureValue(in, Feature{type, unit, 0}, win);
    const float b = featureValue(in, Feature{type, unit, 1}, win);
    EXPECT_NEAR(a, b, 1e-3) << toLetter(type);
  }
}

TEST(Feature, TinyFeaturesKeepEveryCellNonEmpty) {
  const cv::Mat m = randomImage(10, 10, CV_8U, 2);
  const LayerStack s = stackOf(m);
  const std::vector<std::string> names{"intensity"};
  const IntegralStack in(s, names);
  for (int t = 0; t < int(kFeatureTypeCount); ++t) {
    const Feature f{static_cast<FeatureType>(t), Box{0.98, 0.98, 0.02, 0.02}, 0};
    const PixelRect r = featureRectInWindow(f, 5, 5);
    const auto [cols, rows] = featureGrid(f.type);
    EXPECT_GE(r.x1 - r.x0, cols);
    EXPECT_GE(r.y1 - r.y0, rows);
    EXPECT_LE(r.x1, 5);
    EXPECT_LE(r.y1, 5);
    const FeatureLayout l = layoutFeature(f.type, r);
    for (int i = 0; i < l.count(); ++i) {
      EXPECT_GT(l.rects[size_t(i)].x1, l.rects[size_t(i)].x0);
      EXPECT_GT(l.rects[size_t(i)].y1, l.rects[size_t(i)].y0);
    }
    EXPECT_GT(l.blackArea, 0);
    EXPECT_GT(l.whiteArea, 0);
    EXPECT_TRUE(std::isfinite(featureValue(in, f, Box{7, 7, 3, 3})));
  }
}

TEST(Feature, ValidationRejectsRectanglesOutsideTheUnitSquare) {
  EXPECT_NO_THROW(validateFeature(Feature{FeatureType::kChecker, Box{0, 0, 1, 1}, 0}, 1));
  EXPECT_THROW(validateFeature(Feature{FeatureType::kChecker, Box{0.5, 0, 0.6, 1}, 0}, 1), std::invalid_argument);
  EXPECT_THROW(validateFeature(Feature{FeatureType::kChecker, Box{0, 0, 0, 1}, 0}, 1), std::invalid_argument);
  EXPECT_THROW(validateFeature(Feature{FeatureType::kChecker, Box{0, 0, 1, 1}, 1}, 1), std::invalid_argument);
  EXPECT_THROW(validateFeature(Feature{FeatureType::kChecker, Box{NAN, 0, 1, 1}, 0}, 1), std::invalid_argument);
}
