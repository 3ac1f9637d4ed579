// Learned box refinement (boost/box_regression.h): the ridge fit on synthetic data with a known
// answer, its degenerate inputs, the box parametrisation, the features of hand-drawn scenes and
// the refinement of grouped hits.

#include "fusedet/boost/box_regression.h"
#include "fusedet/boost/chain_evaluation.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <random>

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

// n rows of d features drawn uniformly from [-1, 1] (fixed seed) and targets = A x + b.
struct Linear {
  std::vector<std::vector<double>> x;
  std::vector<BoxTargets> y;
};
Linear linearData(std::size_t n, std::size_t d, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Linear out;
  for (std::size_t i = 0; i < n; ++i) {
    std::vector<double> row(d);
    for (double& v : row) v = u(rng);
    BoxTargets t{0.01, -0.02, 0.03, 0.0};
    for (std::size_t j = 0; j < d; ++j)
      for (std::size_t k = 0; k < 4; ++k) t[k] += 0.02 * std::sin(double(1 + j + 7 * k)) * row[j];
    out.x.push_back(row);
    out.y.push_back(t);
  }
  return out;
}

BoxFitParams nearlyPlain() {
  BoxFitParams p;
  p.lambda = 1e-9;  // nearly ordinary least squares
  return p;
}

}  // namespace

TEST(BoxRegression, RecoversAKnownLinearMapOnUnseenRows) {
  const Linear train = linearData(200, 6, 1), test = linearData(50, 6, 2);
  const BoxRegression r = fitBoxRegression(train.x, train.y, nearlyPlain());
  ASSERT_TRUE(r.fitted()) << r.why;
  EXPECT_EQ(r.samples, 200u);
  for (std::size_t i = 0; i < test.x.size(); ++i) {
    const BoxTargets p = r.predict(test.x[i]);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(p[k], test.y[i][k], 1e-6) << "row " << i << " target " << k;
  }
}

// A larger penalty shrinks the weights towards 0: predictions move towards the targets' mean.
TEST(BoxRegression, RidgePenaltyShrinksTowardsTheMean) {
  const Linear train = linearData(100, 3, 3);
  BoxFitParams strong;
  strong.lambda = 1e6;
  const BoxRegression r = fitBoxRegression(train.x, train.y, strong);
  ASSERT_TRUE(r.fitted());
  const BoxTargets p = r.predict(train.x[0]);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(p[k], r.intercept[k], 1e-3);
  EXPECT_NEAR(r.intercept[2], 0.03, 0.01);  // the mean of the third target (0.03 + zero-mean terms)
}

TEST(BoxRegression, NoFitIsTheIdentity) {
  const BoxRegression none;
  EXPECT_FALSE(none.fitted());
  const LayerStack s(100, 50);
  const GroupedBox g{Box{10, 5, 30, 20}, Box{12, 5, 28, 20}, {}, {}};
  EXPECT_EQ(none.refine(g, s), g.box);
  EXPECT_EQ(none.predict(std::vector<double>(3, 1.0)), (BoxTargets{0, 0, 0, 0}));
}

TEST(BoxRegression, NoOrTooFewSamplesIsNoFitAndSaysWhy) {
  const BoxRegression empty = fitBoxRegression({}, {}, BoxFitParams{});
  EXPECT_FALSE(empty.fitted());
  EXPECT_NE(empty.why.find("0 usable samples"), std::string::npos) << empty.why;
  const Linear few = linearData(19, 4, 4);  // minSamples 20
  const BoxRegression r = fitBoxRegression(few.x, few.y, BoxFitParams{});
  EXPECT_FALSE(r.fitted());
  EXPECT_NE(r.why.find("19 usable samples, 20 needed"), std::string::npos) << r.why;
}

// Two identical columns share their weight equally (the ridge term picks the smallest-norm
// solution); a constant column gets weight 0; the predictions stay right.
TEST(BoxRegression, CollinearAndConstantFeaturesHaveADefinedFit) {
  Linear d = linearData(100, 2, 5);
  for (auto& row : d.x) {
    row.push_back(row[0]);  // column 2 = column 0
    row.push_back(4.0);     // column 3 constant
  }
  BoxFitParams p;
  p.lambda = 1e-6;
  const BoxRegression r = fitBoxRegression(d.x, d.y, p);
  ASSERT_TRUE(r.fitted()) << r.why;
  for (std::size_t k = 0; k < 4; ++k) {
    EXPECT_NEAR(r.weights[0][k], r.weights[2][k], 1e-9);
    EXPECT_NEAR(r.weights[3][k], 0.0, 1e-12);
  }
  for (std::size_t i = 0; i < 10; ++i)
    for (std::size_t k = 0; k < 4; ++k) EXPECT_NEAR(r.predict(d.x[i])[k], d.y[i][k], 1e-5);
}

TEST(BoxRegression, NonFiniteSamplesAreLeftOut) {
  const Linear d = linearData(60, 3, 6);
  Linear bad = d;
  bad.x.push_back({std::numeric_limits<double>::quiet_NaN(), 0, 0});
  bad.y.push_back({0, 0, 0, 0});
  bad.x.push_back({0, 0, 0});
  bad.y.push_back({std::numeric_limits<double>::infinity(), 0, 0, 0});
  const BoxRegression a = fitBoxRegression(d.x, d.y, BoxFitParams{}), b = fitBoxRegression(bad.x, bad.y, BoxFitParams{});
  ASSERT_TRUE(b.fitted());
  EXPECT_EQ(b.samples, 60u);
  for (std::size_t k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(a.predict(d.x[0])[k], b.predict(d.x[0])[k]);
}

TEST(BoxRegression, RejectsBadArguments) {
  const Linear d = linearData(30, 3, 7);
  BoxFitParams zero;
  zero.lambda = 0;
  EXPECT_THROW(fitBoxRegression(d.x, d.y, zero), std::invalid_argument);
  std::vector<BoxTargets> shorter(d.y.begin(), d.y.end() - 1);
  EXPECT_THROW(fitBoxRegression(d.x, shorter, BoxFitParams{}), std::invalid_argument);
  Linear ragged = d;
  ragged.x[3].push_back(1);
  EXPECT_THROW(fitBoxRegression(ragged.x, ragged.y, BoxFitParams{}), std::invalid_argument);
  const BoxRegression r = fitBoxRegression(d.x, d.y, BoxFitParams{});
  ASSERT_TRUE(r.fitted());
  EXPECT_THROW(r.predict(std::vector<double>(2, 0.0)), std::invalid_argument);
}

// Predictions are clamped: a shift of at most maxShift of the box, a size factor within maxScale.
TEST(BoxRegression, PredictionsAreClamped) {
  BoxRegression r;
  r.mean = {0};
  r.scale = {1};
  r.weights = {{10, -10, 10, -10}};
  r.maxShift = 0.5;
  r.maxScale = 2;
  const BoxTargets t = r.predict(std::vector<double>{1.0});
  EXPECT_DOUBLE_EQ(t[0], 0.5);
  EXPECT_DOUBLE_EQ(t[1], -0.5);
  EXPECT_DOUBLE_EQ(t[2], std::log(2.0));
  EXPECT_DOUBLE_EQ(t[3], -std::log(2.0));
}

// Box {10, 20, 40, 20} (centre 30, 30) against truth {14, 18, 48, 30} (centre 38, 33):
// dx = 8 / 40 = 0.2, dy = 3 / 20 = 0.15, log(48 / 40), log(30 / 20); applying them gives it back.
TEST(BoxRegression, TargetsAreTheRCnnParametrisation) {
  const Box b{10, 20, 40, 20}, truth{14, 18, 48, 30};
  const BoxTargets t = boxTargets(b, truth);
  EXPECT_DOUBLE_EQ(t[0], 0.2);
  EXPECT_DOUBLE_EQ(t[1], 0.15);
  EXPECT_DOUBLE_EQ(t[2], std::log(1.2));
  EXPECT_DOUBLE_EQ(t[3], std::log(1.5));
  const Box back = applyTargets(b, t);
  EXPECT_NEAR(back.x, 14, 1e-9);
  EXPECT_NEAR(back.y, 18, 1e-9);
  EXPECT_NEAR(back.w, 48, 1e-9);
  EXPECT_NEAR(back.h, 30, 1e-9);
}

// Features of a hand-drawn scene: distance layer 100 x 50 = reference grid, an object at 10 m over
// columns 20..59 and rows 10..39, background 30 m. Base box {25, 10, 30, 30}: the laser extent
// widens it to 18.5 .. 61.5 (laser_extent_test.cpp's first case) = -6.5 / 30 and +6.5 / 30; the
// object's rows are 10..39 -> top 0, bottom 0. Group box {27, 10, 26, 30}: edges +2/30, 0, -2/30, 0.
// Members {25, 10, 30, 30} and {29, 10, 22, 30}: left mean (0 + 4/30) / 2, spread 2/30, min 0, max 4/30.
TEST(BoxRegression, FeaturesOfAHandDrawnScene) {
  LayerStack s(100, 50);
  cv::Mat1f d(50, 100, 30.f);
  d(cv::Rect(20, 10, 40, 30)).setTo(10.f);
  s.set(Layer{std::string(layer::kDistance), d, {}});
  const GroupedBox g{Box{25, 10, 30, 30}, Box{27, 10, 26, 30}, {Box{25, 10, 30, 30}, Box{29, 10, 22, 30}}, {}};
  const std::vector<double> f = boxFeatures(g, s);
  ASSERT_EQ(f.size(), boxFeatureCount());
  EXPECT_NEAR(f[0], 2.0 / 30, 1e-12);
  EXPECT_NEAR(f[1], 0, 1e-12);
  EXPECT_NEAR(f[2], -2.0 / 30, 1e-12);
  EXPECT_NEAR(f[4], 2.0 / 30, 1e-12);   // left: mean
  EXPECT_NEAR(f[5], 2.0 / 30, 1e-12);   // spread
  EXPECT_NEAR(f[6], 0, 1e-12);          // min
  EXPECT_NEAR(f[7], 4.0 / 30, 1e-12);   // max
  EXPECT_NEAR(f[20], std::log(3.0), 1e-12);  // log(1 + 2 members)
  EXPECT_NEAR(f[21], -6.5 / 30, 1e-12);      // laser extent left
  EXPECT_NEAR(f[22], 6.5 / 30, 1e-12);       // right
  EXPECT_NEAR(f[23], 0, 1e-12);              // laser rows: top
  EXPECT_NEAR(f[24], 0, 1e-12);              // bottom
  EXPECT_EQ(f[25], 1.0);                     // the laser saw it
  EXPECT_NEAR(f[26], 0, 1e-12);              // log aspect 30 / 30
  EXPECT_NEAR(f[28], 40.0 / 50, 1e-12);      // bottom / image height
}

TEST(BoxRegression, FeaturesOfDegenerateInputsAreFinite) {
  const LayerStack noLaser(100, 50);
  for (const GroupedBox& g : {GroupedBox{Box{25, 10, 30, 30}, Box{25, 10, 30, 30}, {}, {}},
                              GroupedBox{Box{25, 10, 0, 30}, Box{}, {}, {}},
                              GroupedBox{Box{25, 10, 30, 30}, Box{0, 0, 0, 0}, {Box{}, Box{1e300, 0, 1, 1}}, {}}}) {
    const std::vector<double> f = boxFeatures(g, noLaser);
    ASSERT_EQ(f.size(), boxFeatureCount());
    for (double v : f) EXPECT_TRUE(std::isfinite(v));
  }
  EXPECT_EQ(boxFeatures(GroupedBox{Box{25, 10, 30, 30}, Box{25, 10, 30, 30}, {}, {}}, noLaser)[25], 0.0);  // no laser
}

// refineBoxes(): members are the hits kept in a detection; an intercept-only fit (dx 0.1, others 0)
// moves each box by a tenth of its width; no fit leaves the laser-extent boxes.
TEST(BoxRegression, RefinesGroupedHits) {
  const LayerStack s(200, 100);
  std::vector<Detection> dets(2);
  dets[0].box = Box{10, 10, 40, 20};
  dets[1].box = Box{100, 50, 20, 10};
  const std::vector<std::vector<RawHit>> hits{{RawHit{Box{9, 10, 40, 20}}, RawHit{Box{11, 10, 40, 20}},
                                               RawHit{Box{100, 50, 20, 10}}, RawHit{Box{150, 0, 20, 10}}}};
  std::vector<std::vector<HitFate>> fates{{HitFate{HitFate::Outcome::kKept, 0, 2}, HitFate{HitFate::Outcome::kKept, 0, 2},
                                           HitFate{HitFate::Outcome::kKept, 1, 1},
                                           HitFate{HitFate::Outcome::kTooFewNeighbours, -1, 1}}};
  std::vector<Detection> plain = dets;
  std::vector<GroupedBox> groups;
  refineBoxes(plain, hits, fates, s, LaserExtentParams{}, BoxRegression{}, &groups);
  EXPECT_EQ(plain[0].box, dets[0].box);
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0].members.size(), 2u);
  EXPECT_EQ(groups[1].members.size(), 1u);
  EXPECT_EQ(groups[0].groupBox, dets[0].box);

  BoxRegression shift;
  shift.mean.assign(boxFeatureCount(), 0);
  shift.scale.assign(boxFeatureCount(), 1);
  shift.weights.assign(boxFeatureCount(), {0, 0, 0, 0});
  shift.intercept = {0.1, 0, 0, 0};
  std::vector<Detection> moved = dets;
  refineBoxes(moved, hits, fates, s, LaserExtentParams{}, shift);
  EXPECT_NEAR(moved[0].box.x, 14, 1e-9);
  EXPECT_NEAR(moved[1].box.x, 102, 1e-9);
  EXPECT_NEAR(moved[0].unitBox.x, s.toUnit(moved[0].box).x, 1e-12);
}
