// SPDX-License-Identifier: Apache-2.0
// The scanner (precomputed per-scale offsets, threads) against the obvious per-window path, and
// cascade validation.

#include "fusedet/boost/detector.h"

#include <gtest/gtest.h>

#include <opencv2/core.hpp>
#include <cmath>
#include <random>
#include <string>

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

// A random cascade over two layers whose first stage accepts a fair share of windows.
Cascade randomCascade(unsigned seed) {
  Cascade c;
  c.className = "thing";
  c.windowWidth = 16;
  c.windowHeight = 24;
  c.layers = {"intensity", "distance"};
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(0, 1);
  for (int s = 0; s < 4; ++s) {
    Stage st;
    for (int k = 0; k < 3 + s; ++k) {
      const double x = u(rng) * 0.7, y = u(rng) * 0.7;
      const int fi = c.addFeature(Feature{static_cast<FeatureType>(rng() % 10),
                                          Box{x, y, 0.1 + u(rng) * (0.9 - x), 0.1 + u(rng) * (0.9 - y)},
                                          int(rng() % 2)});
      st.stumps.push_back(Stump{fi, (u(rng) - 0.5) * 20, u(rng) - 0.5, u(rng) - 0.5});
    }
    st.threshold = -0.4;
    c.stages.push_back(st);
  }
  return c;
}

LayerStack randomStack(unsigned seed) {
  LayerStack s(120, 80);
  cv::Mat a(80, 120, CV_8U), d(40, 60, CV_32F);
  cv::RNG rng(seed);
  rng.fill(a, cv::RNG::UNIFORM, 0, 256);
  rng.fill(d, cv::RNG::UNIFORM, 0.0, 40.0);
  s.set(Layer{"intensity", a, {}});
  s.set(Layer{"distance", d, {}});
  return s;
}

// Every window of the documented geometry (sizes from the 16 x 24 base window by the scale factor,
// step 2 x scale; all rounded half up) on the 120 x 80 test stack, decided the slow way by
// evaluateWindow(); `windows` counts them.
std::vector<RawHit> plainScan(const Cascade& c, const IntegralStack& in, const ScanParams& p, std::size_t& windows) {
  std::vector<RawHit> expect;
  windows = 0;
  int scale = 0;
  for (double f = 1;; f *= p.scaleFactor) {
    const int w = int(std::floor(16 * f + 0.5)), h = int(std::floor(24 * f + 0.5));
    if (w > 120 || h > 80) break;
    const int step = std::max(1, int(std::floor(2 * f + 0.5)));
    for (int y = 0; y + h <= 80; y += step)
      for (int x = 0; x + w <= 120; x += step) {
        ++windows;
        const Box box{double(x), double(y), double(w), double(h)};
        const WindowResult r = evaluateWindow(c, in, box);
        if (r.accepted) expect.push_back(RawHit{box, r.score, scale});
      }
    ++scale;
  }
  return expect;
}

}  // namespace

// Both scanners (one pass on the stack, one window at a time on per-layer integrals) decide every
// window as evaluateWindow() does, with its score and scale.
TEST(Detector, ScanAgreesWithPerWindowEvaluationOnEveryWindow) {
  const Cascade c = randomCascade(1);
  const LayerStack s = randomStack(2);
  const IntegralStack in = integrateFor(c, s);
  ScanParams p;
  p.scaleFactor = 1.25;
  p.threads = 1;
  std::size_t windows = 0;
  const std::vector<RawHit> expect = plainScan(c, in, p, windows);
  const Detector det(c);
  for (int path = 0; path < 2; ++path) {
    ScanStats stats;
    const std::vector<RawHit> hits = path == 0 ? det.scan(s, p, &stats) : det.scan(in, p, &stats);
    const std::string what = path == 0 ? "one-pass scanner" : "per-layer scanner";
    EXPECT_EQ(stats.windows, windows) << what;
    ASSERT_EQ(hits.size(), expect.size()) << what;
    ASSERT_GT(hits.size(), 10u) << "the test cascade should accept some windows";
    EXPECT_LT(hits.size(), windows / 2) << "and reject others";
    for (std::size_t i = 0; i < hits.size(); ++i) {
      EXPECT_EQ(hits[i].box, expect[i].box) << what << " hit " << i;
      EXPECT_EQ(hits[i].score, expect[i].score) << what << " hit " << i;
      EXPECT_EQ(hits[i].scale, expect[i].scale) << what << " hit " << i;
    }
  }
}

TEST(Detector, MultiThreadedScanIsIdenticalToSingleThreaded) {
  const Cascade c = randomCascade(3);
  const LayerStack s = randomStack(4);
  const Detector det(c);
  ScanParams p;
  p.threads = 1;
  const auto one = det.scan(s, p);
  for (int threads : {0, 2, 4}) {
    p.threads = threads;
    const auto many = det.scan(s, p);
    ASSERT_EQ(many.size(), one.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(many[i].box, one[i].box);
      EXPECT_EQ(many[i].score, one[i].score);
      EXPECT_EQ(many[i].scale, one[i].scale);
    }
  }
}

TEST(Detector, MinAndMaxSizeLimitTheWindows) {
  const Cascade c = randomCascade(5);
  const LayerStack s = randomStack(6);
  const Detector det(c);
  ScanParams p;
  p.minWidth = 30;
  p.minHeight = 30;
  p.maxWidth = 60;
  p.maxHeight = 70;
  ScanStats stats;
  const auto hits = det.scan(s, p, &stats);
  EXPECT_GT(stats.windows, 0u);
  for (const RawHit& h : hits) {
    EXPECT_GE(h.box.w, 30);
    EXPECT_GE(h.box.h, 30);
    EXPECT_LE(h.box.w, 60);
    EXPECT_LE(h.box.h, 70);
    EXPECT_NEAR(h.box.w / h.box.h, 16.0 / 24.0, 0.05);
  }
}

TEST(Cascade, ValidateNamesTheSourceAndTheProblem) {
  Cascade c = randomCascade(7);
  c.source = "my.model";
  EXPECT_NO_THROW(c.validate());
  auto expectError = [](Cascade bad, const std::string& what) {
    try {
      bad.validate();
      ADD_FAILURE() << "no error for " << what;
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find("my.model"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(what), std::string::npos) << e.what();
    }
  };
  Cascade bad = c;
  bad.stages[1].stumps[0].threshold = NAN;
  expectError(bad, "threshold is not finite");
  bad = c;
  bad.stages[0].stumps[0].feature = 999;
  expectError(bad, "out of range");
  bad = c;
  bad.stages[2].threshold = INFINITY;
  expectError(bad, "stage 2 threshold");
  bad = c;
  bad.stages.clear();
  expectError(bad, "no stages");
  bad = c;
  bad.features[0].rect.w = 2;
  expectError(bad, "unit square");
  bad = c;
  bad.layers[1] = "hue_distance";
  expectError(bad, "reference hue");
}
