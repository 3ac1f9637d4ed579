// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/gentle_boost.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

using namespace fusedet::boosting;

TEST(StageThreshold, KeepsTheRequiredHitRate) {
  std::vector<double> s;
  for (int i = 0; i < 200; ++i) s.push_back(i);  // 0..199
  // 0.995 * 200 = 199 must pass: one may be dropped -> threshold just below 1.
  const double t = stageThreshold(s, 0.995);
  EXPECT_LT(t, 1.0);
  EXPECT_GT(t, 0.0);
  EXPECT_LE(stageThreshold(s, 1.0), 0.0);
  EXPECT_GT(stageThreshold(s, 1.0), -1e-6);
}

TEST(GentleBoost, StageReachesFalseAlarmAtHitRateOnSeparableData) {
  // Two informative features (each alone is weak), eight noise features.
  const std::size_t n = 600, pos = 200, F = 10;
  std::mt19937 rng(7);
  std::normal_distribution<float> g(0, 1);
  std::vector<float> values(F * n);
  for (std::size_t f = 0; f < F; ++f)
    for (std::size_t i = 0; i < n; ++i)
      values[f * n + i] = g(rng) + ((f == 3 || f == 8) && i < pos ? 1.5f : 0.f);
  const FeatureMatrix m = buildFeatureMatrix(F, n, [&](std::size_t first, std::size_t count, std::span<float> out) {
    std::copy(values.begin() + long(first * n), values.begin() + long((first + count) * n), out.begin());
  });
  const FeatureValuesFn raw = [&](std::size_t f, std::span<float> out) {
    std::copy(values.begin() + long(f * n), values.begin() + long((f + 1) * n), out.begin());
  };
  StageConfig c;
  c.minHit = 0.99;
  c.maxFalseAlarm = 0.5;
  int rounds = 0;
  const StageResult r = trainStage(m, pos, raw, c, [&](const RoundInfo& info) { rounds = info.round; });
  EXPECT_TRUE(r.reachedFalseAlarm);
  EXPECT_GE(r.hitRate, 0.99);
  EXPECT_LE(r.falseAlarm, 0.5);
  EXPECT_EQ(rounds, int(r.stumps.size()));
  // The informative features come first and carry most of the stage.
  ASSERT_GE(r.stumps.size(), 2u);
  EXPECT_TRUE(r.stumps[0].feature == 3 || r.stumps[0].feature == 8) << r.stumps[0].feature;
  std::size_t informative = 0;
  for (const auto& s : r.stumps) informative += (s.feature == 3 || s.feature == 8);
  EXPECT_GE(2 * informative, r.stumps.size());
  // Recompute hit/false-alarm rates independently from the stumps.
  std::size_t hits = 0, fas = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (const auto& s : r.stumps) sum += s(values[s.feature * n + i]);
    if (sum >= r.threshold) (i < pos ? hits : fas)++;
  }
  EXPECT_DOUBLE_EQ(double(hits) / pos, r.hitRate);
  EXPECT_DOUBLE_EQ(double(fas) / (n - pos), r.falseAlarm);
}

namespace {
// The worked examples' fixed stump: x < 3.5 ? -1 : +1.
FittedStump fixedStump() {
  FittedStump s;
  s.threshold = 3.5f;
  s.left = -1;
  s.right = 1;
  return s;
}
}  // namespace

// Worked example of the stage threshold: a fixed stump x < 3.5 ? -1 : +1 on positives 5, 6 and
// negatives 1, 2 gives sums +1 +1 / -1 -1: the threshold lies just below 1, no false alarm, one round.
TEST(GentleBoost, ThresholdKeepsMinHitOfTheTrainingPositives) {
  const std::vector<float> train = {5, 6, 1, 2};
  const StumpFinder find = [&](std::span<const float> weights, std::span<float> chosen) {
    EXPECT_EQ(weights.size(), 4u);
    std::copy(train.begin(), train.end(), chosen.begin());
    return fixedStump();
  };
  StageConfig c;
  c.maxWeak = 2;
  int rounds = 0;
  const StageResult r = boostStage(4, 2, find, c, [&](const RoundInfo&) { ++rounds; });
  EXPECT_EQ(rounds, 1);
  EXPECT_NEAR(r.threshold, 1.0, 1e-8);
  EXPECT_LT(r.threshold, 1.0);
  EXPECT_EQ(r.falseAlarm, 0.0);
  EXPECT_EQ(r.hitRate, 1.0);
  EXPECT_TRUE(r.reachedFalseAlarm);
  EXPECT_EQ(r.stumps.size(), 1u);
}
