// Regression trees as weak learners (regression_tree.h): depth 1 is the stump search's stump, a
// depth-2 tree fits an interaction no stump can, a node's histograms are those of its samples
// alone, and the Gentle AdaBoost loop with depth-1 trees is the stump loop.

#include "fusedet/boost/regression_tree.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fusedet/boost/feature_matrix.h"
#include "fusedet/boost/gentle_boost.h"

using namespace fusedet::boosting;

namespace {

// Feature-major values, samples [0, positives) positives, weights summing to 1.
struct Data {
  std::size_t features = 0, samples = 0, positives = 0;
  std::vector<float> values, w;
  std::span<const float> row(std::size_t f) const {
    return std::span<const float>(values).subspan(f * samples, samples);
  }
  FeatureMatrix matrix() const {
    return buildFeatureMatrix(features, samples, [this](std::size_t first, std::size_t count, std::span<float> out) {
      for (std::size_t k = 0; k < count; ++k)
        std::copy(row(first + k).begin(), row(first + k).end(), out.begin() + long(k * samples));
    }, 2, 7);
  }
  FeatureValuesFn raw() const {
    return [this](std::size_t f, std::span<float> out) { std::copy(row(f).begin(), row(f).end(), out.begin()); };
  }
};

Data noise(std::size_t features, std::size_t samples, unsigned seed) {
  Data d;
  d.features = features;
  d.samples = samples;
  d.positives = samples / 3;
  std::mt19937 rng(seed);
  std::normal_distribution<float> n(0, 1);
  std::uniform_real_distribution<float> u(0.1f, 1.0f);
  for (std::size_t f = 0; f < features; ++f)
    for (std::size_t i = 0; i < samples; ++i) d.values.push_back(n(rng) + (i < d.positives ? 0.1f * float(f % 5) : 0.f));
  double sum = 0;
  for (std::size_t i = 0; i < samples; ++i) sum += d.w.emplace_back(u(rng));
  for (float& x : d.w) x = float(x / sum);
  return d;
}

// Positives where features 0 and 1 are both below 0.5 (an AND of two thresholds), feature 2 noise;
// uniform weights. No single threshold separates them.
Data interaction(std::size_t samples, unsigned seed) {
  Data d;
  d.features = 3;
  d.samples = samples;
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.f, 1.f);
  std::vector<std::array<float, 3>> pos, neg;
  while (pos.size() + neg.size() < samples) {
    const std::array<float, 3> x{u(rng), u(rng), u(rng)};
    if (std::fabs(x[0] - 0.5f) < 0.02f || std::fabs(x[1] - 0.5f) < 0.02f) continue;  // a margin around the cuts
    (x[0] < 0.5f && x[1] < 0.5f ? pos : neg).push_back(x);
  }
  d.positives = pos.size();
  pos.insert(pos.end(), neg.begin(), neg.end());
  d.values.resize(3 * samples);
  for (std::size_t f = 0; f < 3; ++f)
    for (std::size_t i = 0; i < samples; ++i) d.values[f * samples + i] = pos[i][f];
  d.w.assign(samples, 1.f / float(samples));
  return d;
}

double squaredError(const Data& d, std::span<const double> f) {
  double e = 0;
  for (std::size_t i = 0; i < d.samples; ++i) {
    const double r = (i < d.positives ? 1.0 : -1.0) - f[i];
    e += d.w[i] * r * r;
  }
  return e;
}

}  // namespace

TEST(RegressionTree, DepthOneIsTheStumpSearchsStump) {
  const Data d = noise(30, 400, 3);
  const FeatureMatrix m = d.matrix();
  const FittedStump s = findBestStump(m, d.positives, d.w, d.raw());
  TreeSearchOptions o;
  o.depth = 1;
  std::vector<double> out(d.samples);
  const FittedTree t = fitRegressionTree(m, d.positives, d.w, d.raw(), o, out);
  ASSERT_EQ(t.nodes.size(), 1u);
  EXPECT_EQ(t.nodes[0].feature, s.feature);
  EXPECT_EQ(t.nodes[0].threshold, s.threshold);
  ASSERT_EQ(t.leaves, (std::vector<double>{s.left, s.right}));
  EXPECT_EQ(t.nodes[0].left, 0);
  EXPECT_EQ(t.nodes[0].right, -1);
  for (std::size_t i = 0; i < d.samples; ++i) EXPECT_EQ(out[i], s(d.row(s.feature)[i])) << i;
  EXPECT_NEAR(t.error, s.error, 1e-9);
}

TEST(RegressionTree, DepthTwoFitsAnInteractionNoStumpCan) {
  const Data d = interaction(600, 4);
  const FeatureMatrix m = d.matrix();
  const FittedStump s = findBestStump(m, d.positives, d.w, d.raw());
  EXPECT_GT(s.error, 0.4) << "one threshold cannot separate an AND (total weight 1)";
  TreeSearchOptions o;
  o.depth = 2;
  std::vector<double> out(d.samples);
  const FittedTree t = fitRegressionTree(m, d.positives, d.w, d.raw(), o, out);
  EXPECT_LT(t.error, 1e-12) << "two levels separate it exactly";
  EXPECT_NEAR(squaredError(d, out), t.error, 1e-12);
  // The root splits one informative feature near 0.5; its right side (>= 0.5) holds negatives only
  // and is a leaf, its left side splits the other feature near 0.5 into two pure leaves.
  ASSERT_EQ(t.nodes.size(), 2u);
  ASSERT_EQ(t.leaves.size(), 3u);
  EXPECT_LT(t.nodes[0].feature, 2u);
  EXPECT_EQ(t.nodes[1].feature, 1 - t.nodes[0].feature);
  for (const auto& n : t.nodes) EXPECT_NEAR(n.threshold, 0.5, 0.021);
  EXPECT_EQ(t.nodes[0].left, 1);
  EXPECT_EQ(t.nodes[0].right, -2);
  EXPECT_EQ(t.nodes[1].left, 0);
  EXPECT_EQ(t.nodes[1].right, -1);
  EXPECT_EQ(t.leaves, (std::vector<double>{1.0, -1.0, -1.0}));
  // operator() follows the same paths as the outputs written.
  for (std::size_t i = 0; i < d.samples; ++i)
    EXPECT_EQ(t([&](std::size_t k) { return d.row(t.nodes[k].feature)[i]; }), out[i]) << i;
  // And the cascade's form (features mapped) decides alike with treeLeaf().
  const Tree c = toCascadeTree(t, [](std::size_t f) { return int(f) + 10; });
  for (std::size_t i = 0; i < d.samples; ++i)
    EXPECT_EQ(treeLeaf(c, [&](std::size_t k) { return d.row(std::size_t(c.nodes[k].feature - 10))[i]; }), out[i]);
}

TEST(RegressionTree, PureOrUnsplittableChildrenBecomeLeaves) {
  // Feature 0 alone separates the classes: the root splits it, both children are pure leaves.
  Data d = noise(4, 200, 5);
  for (std::size_t i = 0; i < d.samples; ++i) d.values[i] = i < d.positives ? 2.f : -2.f;
  const FeatureMatrix m = d.matrix();
  TreeSearchOptions o;
  o.depth = 3;
  std::vector<double> out(d.samples);
  const FittedTree t = fitRegressionTree(m, d.positives, d.w, d.raw(), o, out);
  ASSERT_EQ(t.nodes.size(), 1u);
  EXPECT_EQ(t.nodes[0].feature, 0u);
  EXPECT_EQ(t.leaves, (std::vector<double>{-1.0, 1.0}));
  EXPECT_LT(t.error, 1e-12);
}

TEST(RegressionTree, NodeHistogramsAreThoseOfItsSamplesAlone) {
  // The node search against the whole-matrix search with every other sample's weight zero (the
  // same histograms, summed in another order): the same candidates, gains within float rounding.
  const Data d = noise(40, 500, 6);
  const FeatureMatrix m = d.matrix();
  std::vector<std::uint32_t> node;
  std::vector<float> nodeW, masked(d.samples, 0.f);
  std::size_t nodePos = 0;
  for (std::uint32_t i = 0; i < d.samples; ++i)
    if (d.row(3)[i] < 0.2f) {
      node.push_back(i);
      nodeW.push_back(d.w[i]);
      masked[i] = d.w[i];
      nodePos += i < d.positives;
    }
  ASSERT_GT(node.size(), 100u);
  ASSERT_LT(node.size(), 400u);
  const auto got = bestBinnedSplits(m, node, nodePos, nodeW, 5, 2);
  const auto want = bestBinnedSplits(m, d.positives, masked, 5, 2);
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t k = 0; k < got.size(); ++k) {
    EXPECT_EQ(got[k].feature, want[k].feature) << k;
    EXPECT_EQ(got[k].bin, want[k].bin) << k;
    EXPECT_NEAR(got[k].gain, want[k].gain, 1e-5 * want[k].gain) << k;
  }
  // Bad node lists are refused.
  std::vector<std::uint32_t> unsorted = {5, 3};
  std::vector<float> two(2, 0.5f);
  EXPECT_THROW(bestBinnedSplits(m, unsorted, 0, two, 1), std::invalid_argument);
  std::vector<std::uint32_t> outside = {1, std::uint32_t(d.samples)};
  EXPECT_THROW(bestBinnedSplits(m, outside, 0, two, 1), std::invalid_argument);
  EXPECT_THROW(bestBinnedSplits(m, node, nodePos, two, 1), std::invalid_argument);
}

TEST(RegressionTree, ArgumentsAreChecked) {
  const Data d = noise(3, 50, 7);
  const FeatureMatrix m = d.matrix();
  std::vector<double> out(d.samples), shortOut(3);
  TreeSearchOptions o;
  o.depth = 0;
  EXPECT_THROW(fitRegressionTree(m, d.positives, d.w, d.raw(), o, out), std::invalid_argument);
  o.depth = 2;
  EXPECT_THROW(fitRegressionTree(m, d.positives, d.w, d.raw(), o, shortOut), std::invalid_argument);
}

TEST(GentleBoost, TreeStagesOfDepthOneAreTheStumpStages) {
  const Data d = noise(30, 300, 8);
  const FeatureMatrix m = d.matrix();
  StageConfig c;
  c.maxWeak = 12;
  c.maxFalseAlarm = 0.05;
  c.threads = 2;
  const StageResult stumps = trainStage(m, d.positives, d.raw(), c);
  c.treeDepth = 1;
  const StageResult trees = trainTreeStage(m, d.positives, d.raw(), c);
  ASSERT_EQ(trees.trees.size(), stumps.stumps.size());
  EXPECT_TRUE(trees.stumps.empty());
  for (std::size_t k = 0; k < trees.trees.size(); ++k) {
    const FittedTree& t = trees.trees[k];
    const FittedStump& s = stumps.stumps[k];
    ASSERT_EQ(t.nodes.size(), 1u);
    EXPECT_EQ(t.nodes[0].feature, s.feature) << k;
    EXPECT_EQ(t.nodes[0].threshold, s.threshold) << k;
    EXPECT_EQ(t.leaves, (std::vector<double>{s.left, s.right})) << k;
  }
  EXPECT_EQ(trees.threshold, stumps.threshold);
  EXPECT_EQ(trees.hitRate, stumps.hitRate);
  EXPECT_EQ(trees.falseAlarm, stumps.falseAlarm);
}

TEST(GentleBoost, DepthTwoTreesReachAStageTargetInFewerRoundsOnAnInteraction) {
  const Data d = interaction(600, 9);
  const FeatureMatrix m = d.matrix();
  StageConfig c;
  c.maxWeak = 30;
  c.maxFalseAlarm = 0.05;
  c.minHit = 0.99;
  c.threads = 1;
  const StageResult stumps = trainStage(m, d.positives, d.raw(), c);
  c.treeDepth = 2;
  int rounds = 0;
  const StageResult trees = trainTreeStage(m, d.positives, d.raw(), c, [&](const RoundInfo& r) {
    ASSERT_NE(r.tree, nullptr);
    rounds = r.round;
  });
  EXPECT_TRUE(trees.reachedFalseAlarm);
  EXPECT_EQ(trees.trees.size(), 1u) << "one depth-2 tree separates the AND";
  EXPECT_EQ(rounds, 1);
  EXPECT_GE(stumps.stumps.size(), 2u) << "one stump leaves a third of the negatives with the positives";
}
