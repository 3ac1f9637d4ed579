// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/stump.h"

#include <gtest/gtest.h>

#include <cmath>
#include <array>
#include <limits>
#include <random>

#include "fusedet/boost/feature_matrix.h"

using namespace fusedet::boosting;

namespace {

struct Data {
  std::size_t features, samples, positives;
  std::vector<float> values;  // feature-major
  std::vector<float> w;
  std::span<const float> row(std::size_t f) const {
    return std::span<const float>(values).subspan(f * samples, samples);
  }
};

Data makeData(std::size_t features, std::size_t samples, unsigned seed, int distinct = 0) {
  Data d{features, samples, samples / 3, {}, {}};
  std::mt19937 rng(seed);
  std::normal_distribution<float> noise(0, 1);
  std::uniform_real_distribution<float> u(0.1f, 1.0f);
  d.values.resize(features * samples);
  for (std::size_t f = 0; f < features; ++f)
    for (std::size_t i = 0; i < samples; ++i) {
      float v = noise(rng) + (i < d.positives ? 0.05f * float(f % 7) : 0.f);
      if (distinct > 0) v = std::round(v * float(distinct) / 8) ;  // few distinct values
      d.values[f * samples + i] = v;
    }
  double sum = 0;
  for (std::size_t i = 0; i < samples; ++i) {
    d.w.push_back(u(rng));
    sum += d.w.back();
  }
  for (float& x : d.w) x = float(x / sum);
  return d;
}

// Independent brute force: every threshold between two sorted values, errors summed directly.
double bruteForceError(const Data& d, std::size_t f, double* bestThreshold = nullptr) {
  const auto v = d.row(f);
  std::vector<float> cuts(v.begin(), v.end());
  std::sort(cuts.begin(), cuts.end());
  cuts.push_back(std::numeric_limits<float>::infinity());
  double best = 1e300;
  for (float t : cuts) {
    double wl = 0, sl = 0, wr = 0, sr = 0;
    for (std::size_t i = 0; i < d.samples; ++i) {
      const double y = i < d.positives ? 1 : -1;
      (v[i] < t ? wl : wr) += d.w[i];
      (v[i] < t ? sl : sr) += d.w[i] * y;
    }
    const double cl = wl > 0 ? sl / wl : 0, cr = wr > 0 ? sr / wr : 0;
    double e = 0;
    for (std::size_t i = 0; i < d.samples; ++i) {
      const double y = i < d.positives ? 1 : -1;
      const double p = v[i] < t ? cl : cr;
      e += d.w[i] * (y - p) * (y - p);
    }
    if (e < best - 1e-15) {
      best = e;
      if (bestThreshold) *bestThreshold = t;
    }
  }
  return best;
}

FeatureMatrix binned(const Data& d) {
  return buildFeatureMatrix(d.features, d.samples, [&](std::size_t first, std::size_t count, std::span<float> out) {
    for (std::size_t k = 0; k < count; ++k)
      std::copy(d.row(first + k).begin(), d.row(first + k).end(), out.begin() + long(k * d.samples));
  }, 2, 7);
}

FeatureValuesFn rawOf(const Data& d) {
  return [&d](std::size_t f, std::span<float> out) { std::copy(d.row(f).begin(), d.row(f).end(), out.begin()); };
}

}  // namespace

TEST(BinEdges, FewDistinctValuesGetOneBinEach) {
  const std::vector<float> v = {3, 1, 2, 2, 5, 1, 3};
  const auto e = binEdges(v);
  EXPECT_EQ(e, (std::vector<float>{2, 3, 5}));
  FeatureMatrix m(1, v.size());
  m.setFeature(0, v);
  const std::uint8_t expected[] = {2, 0, 1, 1, 3, 0, 2};  // dense ranks of the distinct values
  for (std::size_t i = 0; i < v.size(); ++i) EXPECT_EQ(m.row(0)[i], expected[i]) << i;
  // Negative values, zero signs and NaN keep their order (NaN last).
  const std::vector<float> w = {-0.5f, 2.f, -3.f, 0.f, NAN, 1e-30f};
  FeatureMatrix m2(1, w.size());
  m2.setFeature(0, w);
  const std::uint8_t expected2[] = {1, 4, 0, 2, 5, 3};
  for (std::size_t i = 0; i < w.size(); ++i) EXPECT_EQ(m2.row(0)[i], expected2[i]) << i;
}

TEST(BinEdges, ManyValuesGiveOrderPreservingBins) {
  std::vector<float> v;
  for (int i = 0; i < 5000; ++i) v.push_back(std::sin(float(i)) * 100);
  const auto e = binEdges(v);
  EXPECT_LE(e.size(), 255u);
  EXPECT_GE(e.size(), 200u);
  EXPECT_TRUE(std::is_sorted(e.begin(), e.end()));
  FeatureMatrix m(1, v.size());
  m.setFeature(0, v);
  std::size_t bad = 0;
  std::array<int, 256> perBin{};
  for (std::size_t i = 0; i < v.size(); ++i) {
    perBin[m.row(0)[i]]++;
    for (std::size_t j = 0; j < v.size(); j += 97) {
      bad += (v[i] < v[j] && m.row(0)[i] > m.row(0)[j]) || (v[i] == v[j] && m.row(0)[i] != m.row(0)[j]);
    }
  }
  EXPECT_EQ(bad, 0u);
  // Equal-count quantiles: 5000 / 256 = 19.5 values per bin.
  for (int b = 0; b < 256; ++b) EXPECT_NEAR(perBin[b], 5000.0 / 256, 2) << b;
}

TEST(Stump, ExactFitEqualsBruteForce) {
  const Data d = makeData(6, 150, 1);
  for (std::size_t f = 0; f < d.features; ++f) {
    const FittedStump s = fitStumpExact(f, d.row(f), d.w, d.positives);
    EXPECT_NEAR(s.error, bruteForceError(d, f), 1e-9) << f;
    EXPECT_NEAR(stumpSquaredError(s, d.row(f), d.w, d.positives), s.error, 1e-9);
  }
}

TEST(Stump, HistogramSearchFindsTheBruteForceOptimumWhenBinsAreExact) {
  const Data d = makeData(40, 300, 2, /*distinct=*/40);  // <= 256 distinct values per feature
  const FeatureMatrix m = binned(d);
  double best = 1e300;
  std::size_t bestF = 0;
  for (std::size_t f = 0; f < d.features; ++f) {
    const double e = bruteForceError(d, f);
    if (e < best - 1e-12) {
      best = e;
      bestF = f;
    }
  }
  const FittedStump s = findBestStump(m, d.positives, d.w, rawOf(d), {2, 1});
  EXPECT_EQ(s.feature, bestF);
  EXPECT_NEAR(s.error, best, 1e-6);
}

TEST(Stump, QuantisedSearchWithRefinementIsWithinOnePercentOfExhaustive) {
  const Data d = makeData(60, 2000, 3);
  const FeatureMatrix m = binned(d);
  double best = 1e300;
  for (std::size_t f = 0; f < d.features; ++f)
    best = std::min(best, fitStumpExact(f, d.row(f), d.w, d.positives).error);
  const FittedStump s = findBestStump(m, d.positives, d.w, rawOf(d), {2, 4});
  EXPECT_LE(s.error, best * 1.01);
  EXPECT_GE(s.error, best - 1e-12);
}

TEST(Stump, TiesGoToTheSmallerFeatureAndThreadsDoNotMatter) {
  Data d = makeData(20, 200, 4);
  // Features 5, 11 and 17 are identical and the best by far.
  for (std::size_t i = 0; i < d.samples; ++i) {
    const float v = (i < d.positives ? 2.f : -2.f) + 0.01f * float(i % 13);
    for (std::size_t f : {5u, 11u, 17u}) d.values[f * d.samples + i] = v;
  }
  const FeatureMatrix m = binned(d);
  const FittedStump one = findBestStump(m, d.positives, d.w, rawOf(d), {1, 4});
  const FittedStump two = findBestStump(m, d.positives, d.w, rawOf(d), {2, 4});
  EXPECT_EQ(one.feature, 5u);
  EXPECT_EQ(two.feature, 5u);
  EXPECT_EQ(one.threshold, two.threshold);
  EXPECT_EQ(one.left, two.left);
  const auto top = bestBinnedSplits(m, d.positives, d.w, 3, 2);
  ASSERT_EQ(top.size(), 3u);
  EXPECT_EQ(top[0].feature, 5u);
  EXPECT_EQ(top[1].feature, 11u);
  EXPECT_EQ(top[2].feature, 17u);
}

TEST(Stump, RejectsMismatchedSizes) {
  const Data d = makeData(3, 50, 5);
  const FeatureMatrix m = binned(d);
  std::vector<float> w(49, 0.02f);
  EXPECT_THROW(bestBinnedSplits(m, d.positives, w, 1), std::invalid_argument);
  EXPECT_THROW(findBestStump(FeatureMatrix(), 0, {}, rawOf(d)), std::invalid_argument);
}
