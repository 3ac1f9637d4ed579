// Group verifier (boost/group_verifier.h): the logistic fit on synthetic data with a known answer,
// its degenerate inputs, the operating threshold, the height gate, the physical features of a
// hand-drawn scene and the renumbering of hit fates when groups are dropped.

#include "fusedet/boost/group_verifier.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <opencv2/core.hpp>
#include <random>

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

// n rows of d features uniform in [-1, 1]; label = feature 0 + 0.5 feature 1 > margin (separable
// with a gap when margin > 0: rows inside the gap are left out).
struct Labelled {
  std::vector<std::vector<double>> x;
  std::vector<bool> y;
};
Labelled separable(std::size_t n, std::size_t d, unsigned seed, double gap) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1, 1);
  Labelled out;
  while (out.x.size() < n) {
    std::vector<double> row(d);
    for (double& v : row) v = u(rng);
    const double s = row[0] + 0.5 * row[1];
    if (std::abs(s) < gap) continue;
    out.x.push_back(row);
    out.y.push_back(s > 0);
  }
  return out;
}

VerifierParams logistic(double lambda = 0.01, std::size_t minSamples = 20) {
  VerifierParams p;
  p.lambda = lambda;
  p.minSamples = minSamples;
  return p;
}

// A stack of the reference size 100 x 50 whose distance layer (same grid) has an object at 10 m
// over columns 20..59, rows 10..39, and 30 m elsewhere.
LayerStack handDrawn() {
  LayerStack s(100, 50);
  cv::Mat1f d(50, 100, 30.f);
  d(cv::Rect(20, 10, 40, 30)).setTo(10.f);
  s.set(Layer{std::string(layer::kDistance), d, {}});
  return s;
}

}  // namespace

TEST(GroupVerifier, SeparatesSeparableDataOnUnseenRows) {
  const Labelled train = separable(300, 5, 1, 0.1), test = separable(200, 5, 2, 0.25);
  const GroupVerifier v = fitGroupVerifier(train.x, train.y, 0, logistic());
  ASSERT_TRUE(v.fitted()) << v.why;
  EXPECT_EQ(v.samples, 300u);
  for (std::size_t i = 0; i < test.x.size(); ++i) {
    EXPECT_EQ(v.accepts(test.x[i]), test.y[i]) << "row " << i;
    EXPECT_EQ(v.probability(test.x[i]) > 0.5, test.y[i]) << "row " << i;
    EXPECT_TRUE(std::isfinite(v.probability(test.x[i])));
  }
  // The features that decide weigh most, in the generating ratio's direction.
  EXPECT_GT(v.weights[0], v.weights[1]);
  EXPECT_GT(v.weights[1], 0);
  for (std::size_t j = 2; j < 5; ++j) EXPECT_LT(std::abs(v.weights[j]), std::abs(v.weights[1])) << j;
  EXPECT_DOUBLE_EQ(v.trainingF, 1.0);  // every hit kept, no false alarm
}

// A larger penalty shrinks the weights: probabilities move towards the hits' share.
TEST(GroupVerifier, PenaltyShrinksTheWeights) {
  const Labelled data = separable(200, 3, 3, 0.0);
  const GroupVerifier loose = fitGroupVerifier(data.x, data.y, 0, logistic(0.1));
  const GroupVerifier tight = fitGroupVerifier(data.x, data.y, 0, logistic(1000));
  ASSERT_TRUE(loose.fitted() && tight.fitted());
  EXPECT_LT(std::abs(tight.weights[0]), std::abs(loose.weights[0]) / 5);
}

// The operating threshold maximises F = 2 hits / (kept + positives) on the training samples,
// counting the positives no sample hit. One feature: hits at 3, 4, 5, false alarms at 1, 2 and 3.5.
TEST(GroupVerifier, ThresholdHasTheHighestTrainingF) {
  const std::vector<std::vector<double>> x{{1}, {2}, {3}, {3.5}, {4}, {5}};
  const std::vector<bool> y{false, false, true, false, true, true};
  // Ranking 5, 4, 3.5, 3, 2, 1 (monotone weight). With 3 positives: F at k kept = 2h / (k + 3):
  // k=1 2/4, k=2 4/5 = 0.8, k=3 4/6, k=4 6/7 = 0.857 (best), k=5 6/8, k=6 6/9.
  const GroupVerifier v = fitGroupVerifier(x, y, 3, logistic(0.01, 6));
  ASSERT_TRUE(v.fitted()) << v.why;
  EXPECT_NEAR(v.trainingF, 6.0 / 7, 1e-12);
  EXPECT_TRUE(v.accepts(std::vector<double>{3}));
  EXPECT_FALSE(v.accepts(std::vector<double>{2}));
  // 10 positives on the frames (7 never detected): keeping more pays, F at k=6 is 6/16 < k=4's 6/14.
  const GroupVerifier many = fitGroupVerifier(x, y, 10, logistic(0.01, 6));
  EXPECT_NEAR(many.trainingF, 6.0 / 14, 1e-12);
}

TEST(GroupVerifier, DegenerateInputsHaveADefinedOutcome) {
  // No samples, too few, one class only: no fit, says why, keeps everything with its score.
  const GroupVerifier none = fitGroupVerifier({}, {}, 5, logistic());
  EXPECT_FALSE(none.fitted());
  EXPECT_NE(none.why.find("0 usable samples"), std::string::npos) << none.why;
  const Labelled data = separable(40, 3, 4, 0.1);
  const std::vector<bool> allHits(40, true), noHits(40, false);
  const GroupVerifier onlyHits = fitGroupVerifier(data.x, allHits, 40, logistic());
  EXPECT_FALSE(onlyHits.fitted());
  EXPECT_NE(onlyHits.why.find("no false alarm"), std::string::npos) << onlyHits.why;
  const GroupVerifier onlyFalse = fitGroupVerifier(data.x, noHits, 0, logistic());
  EXPECT_FALSE(onlyFalse.fitted());
  EXPECT_NE(onlyFalse.why.find("no hit"), std::string::npos) << onlyFalse.why;
  for (const GroupVerifier& v : {none, onlyHits, onlyFalse}) {
    EXPECT_TRUE(v.accepts(data.x[0]));
    EXPECT_EQ(v.score(data.x[0], 17.0), 17.0);
  }
  // Constant features: weight 0, the fit is the hits' share (intercept only).
  const std::vector<std::vector<double>> constant(30, std::vector<double>{2.0, -1.0});
  std::vector<bool> y(30, false);
  for (std::size_t i = 0; i < 10; ++i) y[i] = true;
  const GroupVerifier flat = fitGroupVerifier(constant, y, 10, logistic());
  ASSERT_TRUE(flat.fitted()) << flat.why;
  EXPECT_EQ(flat.weights[0], 0.0);
  EXPECT_EQ(flat.weights[1], 0.0);
  EXPECT_NEAR(flat.probability(constant[0]), 1.0 / 3, 1e-6);
  // Non-finite rows are left out.
  Labelled withNan = separable(40, 2, 5, 0.1);
  withNan.x.push_back({std::numeric_limits<double>::quiet_NaN(), 0});
  withNan.y.push_back(true);
  EXPECT_EQ(fitGroupVerifier(withNan.x, withNan.y, 0, logistic()).samples, 40u);
}

TEST(GroupVerifier, RejectsBadArguments) {
  const Labelled data = separable(30, 2, 6, 0.1);
  EXPECT_THROW(fitGroupVerifier(data.x, data.y, 0, logistic(0)), std::invalid_argument);
  EXPECT_THROW(fitGroupVerifier(data.x, std::vector<bool>(3, true), 0, logistic()), std::invalid_argument);
  std::vector<std::vector<double>> ragged = data.x;
  ragged[3].push_back(1);
  EXPECT_THROW(fitGroupVerifier(ragged, data.y, 0, logistic()), std::invalid_argument);
  const GroupVerifier v = fitGroupVerifier(data.x, data.y, 0, logistic());
  EXPECT_THROW(v.probability(std::vector<double>{1, 2, 3}), std::invalid_argument);
}

// Physical cues of a hand-drawn scene (handDrawn()): box {25, 10, 30, 30} lies on the object; its
// band (rows 35-85 %, middle half of the columns) is all at 10 m.
TEST(GroupVerifier, PhysicalFeaturesOfAHandDrawnScene) {
  const LayerStack s = handDrawn();
  GroupedBox g{Box{25, 10, 30, 30}, Box{25, 10, 30, 30}, {Box{25, 10, 30, 30}, Box{27, 10, 30, 30}}, {2.0, 4.0}};
  const std::vector<double> f = groupFeatures(g, s);
  ASSERT_EQ(f.size(), groupFeatureCount());
  const std::size_t m = boxFeatureCount();
  EXPECT_NEAR(f[m], 3.0, 1e-12);      // mean last-stage sum
  EXPECT_NEAR(f[m + 1], 4.0, 1e-12);  // max
  EXPECT_NEAR(f[m + 2], 2.0, 1e-12);  // min
  const std::size_t l = laserSeenIndex();
  EXPECT_EQ(f[l], 1.0);
  EXPECT_NEAR(f[l + 1], 1.0, 1e-12);             // every band cell measured
  EXPECT_NEAR(f[l + 2], std::log(10.0), 1e-6);   // median distance
  EXPECT_NEAR(f[l + 3], 0.0, 1e-12);             // no spread
  EXPECT_EQ(pixelMetreHeightIndex(), l + 4);
  EXPECT_NEAR(f[l + 4], std::log(30.0 * 10.0), 1e-6);  // pixel height x distance
  EXPECT_NEAR(f[l + 5], std::log(30.0 * 10.0), 1e-6);  // pixel width x distance
  for (std::size_t j = l + 6; j < l + 9; ++j) EXPECT_EQ(f[j], 0.0) << "no height layer: " << j;
  ASSERT_EQ(f.size(), l + 11);
  EXPECT_NEAR(f[l + 9], std::pow(std::log(300.0), 2), 1e-6);  // squares: log(px height x distance)
  EXPECT_EQ(f[l + 10], 0.0);                                  // and the top's (no height layer)
  // The same object twice as far (20 m) at half the pixel height has the same metric height.
  LayerStack far(100, 50);
  cv::Mat1f d(50, 100, 40.f);
  d(cv::Rect(20, 10, 40, 30)).setTo(20.f);
  far.set(Layer{std::string(layer::kDistance), d, {}});
  const std::vector<double> ff = groupFeatures(GroupedBox{Box{25, 10, 30, 15}, Box{25, 10, 30, 15}, {}, {}}, far);
  EXPECT_NEAR(ff[pixelMetreHeightIndex()], std::log(15.0 * 20.0), 1e-6);
  EXPECT_NEAR(ff[pixelMetreHeightIndex()], f[pixelMetreHeightIndex()], 1e-6);
  // A height layer: object top 1.5 m (rows 13..33), ground 0 under it (34..39); rows 0..12 hold 99
  // but are masked: read, they would be the box's 90th percentile.
  LayerStack withHeight = handDrawn();
  cv::Mat1f h(50, 100, 0.f);
  h(cv::Rect(20, 10, 40, 24)).setTo(1.5f);
  h(cv::Rect(0, 0, 100, 13)).setTo(99.f);
  cv::Mat1b valid(50, 100, std::uint8_t{255});
  valid(cv::Rect(0, 0, 100, 13)).setTo(0);
  withHeight.set(Layer{std::string(kHeightLayerName), h, valid});
  const std::vector<double> fh = groupFeatures(g, withHeight);
  EXPECT_EQ(fh[l + 6], 1.0);
  EXPECT_NEAR(fh[l + 7], 1.5, 1e-6);  // 90th percentile of the box: the object's top
  EXPECT_NEAR(fh[l + 8], 0.0, 1e-6);  // bottom fifth (rows 34..39): the ground
  EXPECT_NEAR(fh[l + 10], 2.25, 1e-6);
}

TEST(GroupVerifier, FeaturesOfDegenerateInputsAreFinite) {
  const LayerStack noLaser(100, 50);
  for (const GroupedBox& g : {GroupedBox{Box{25, 10, 30, 30}, Box{25, 10, 30, 30}, {}, {}},
                              GroupedBox{Box{25, 10, 0, 30}, Box{}, {}, {}},
                              GroupedBox{Box{-50, -50, 10, 10}, Box{}, {Box{}}, {std::numeric_limits<double>::infinity()}}}) {
    for (const LayerStack* s : {&noLaser}) {
      const std::vector<double> f = groupFeatures(g, *s);
      ASSERT_EQ(f.size(), groupFeatureCount());
      for (double v : f) EXPECT_TRUE(std::isfinite(v));
      EXPECT_EQ(f[laserSeenIndex()], 0.0);
    }
  }
  const std::vector<double> outside = groupFeatures(GroupedBox{Box{-50, -50, 10, 10}, Box{}, {}, {}}, handDrawn());
  for (double v : outside) EXPECT_TRUE(std::isfinite(v));
}

// The gate keeps groups whose pixel height x distance lies within the hits' percentile range;
// a group without laser cells is kept; scores stay.
TEST(GroupVerifier, HeightGateKeepsTheHitsRange) {
  const std::size_t n = groupFeatureCount();
  std::vector<std::vector<double>> x;
  std::vector<bool> y;
  for (int i = 0; i < 50; ++i) {
    std::vector<double> row(n, 0.0);
    row[laserSeenIndex()] = 1;
    row[pixelMetreHeightIndex()] = 5.0 + i * 0.01;  // hits: 5.00 .. 5.49
    x.push_back(row);
    y.push_back(true);
    row[pixelMetreHeightIndex()] = 3.0;  // false alarms much lower
    x.push_back(row);
    y.push_back(false);
  }
  VerifierParams p;
  p.kind = VerifierParams::Kind::kHeightGate;
  p.gateLow = 0;
  p.gateHigh = 1;
  const GroupVerifier v = fitGroupVerifier(x, y, 50, p);
  ASSERT_TRUE(v.fitted()) << v.why;
  EXPECT_NEAR(v.gateLow, 5.0, 1e-6);
  EXPECT_NEAR(v.gateHigh, 5.49, 1e-6);
  std::vector<double> probe(n, 0.0);
  probe[laserSeenIndex()] = 1;
  probe[pixelMetreHeightIndex()] = 5.2;
  EXPECT_TRUE(v.accepts(probe));
  EXPECT_EQ(v.score(probe, 9.0), 9.0);
  probe[pixelMetreHeightIndex()] = 3.0;
  EXPECT_FALSE(v.accepts(probe));
  probe[laserSeenIndex()] = 0;
  EXPECT_TRUE(v.accepts(probe));
  // Too few hits with laser cells: no gate.
  p.minSamples = 60;
  EXPECT_FALSE(fitGroupVerifier(x, y, 50, p).fitted());
}

// verifyGroups(): a rejected group leaves the output, its members become kTooFewNeighbours, later
// detections' fates are renumbered, kept ones are rescored.
TEST(GroupVerifier, DroppedGroupsRenumberTheFates) {
  const LayerStack s = handDrawn();
  std::vector<Detection> dets(3);
  dets[0].box = Box{25, 10, 30, 30};
  dets[1].box = Box{70, 5, 20, 10};
  dets[2].box = Box{30, 12, 24, 26};
  for (Detection& d : dets) d.score = 5;
  std::vector<GroupedBox> groups;
  for (const Detection& d : dets) groups.push_back(GroupedBox{d.box, d.box, {}, {}});
  std::vector<std::vector<HitFate>> fates{{HitFate{HitFate::Outcome::kKept, 0, 2}, HitFate{HitFate::Outcome::kKept, 1, 2},
                                           HitFate{HitFate::Outcome::kKept, 2, 2},
                                           HitFate{HitFate::Outcome::kTooFewNeighbours, -1, 1}}};
  // A verifier on the median distance alone: a hit when it is below 20 m (detection 1 lies on the
  // 30 m background).
  GroupVerifier v;
  v.ready = true;
  v.mean.assign(groupFeatureCount(), 0);
  v.scale.assign(groupFeatureCount(), 1);
  v.weights.assign(groupFeatureCount(), 0);
  v.weights[laserSeenIndex() + 2] = -10;  // log distance
  v.intercept = 10 * std::log(20.0);
  v.threshold = 0.5;
  std::vector<Detection> out = dets;
  verifyGroups(out, groups, fates, s, v);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].box, dets[0].box);
  EXPECT_EQ(out[1].box, dets[2].box);
  EXPECT_NEAR(out[0].score, 1 / (1 + std::pow(10.0 / 20.0, 10)), 1e-9);
  EXPECT_EQ(fates[0][0].detection, 0);
  EXPECT_EQ(fates[0][1].detection, -1);
  EXPECT_EQ(fates[0][1].outcome, HitFate::Outcome::kTooFewNeighbours);
  EXPECT_EQ(fates[0][2].detection, 1);
  EXPECT_EQ(fates[0][3].detection, -1);
  // Unfitted: nothing changes.
  std::vector<Detection> same = dets;
  verifyGroups(same, groups, fates, s, GroupVerifier{});
  EXPECT_EQ(same.size(), 3u);
  EXPECT_THROW(verifyGroups(same, {}, fates, s, v), std::invalid_argument);
}
