// SPDX-License-Identifier: Apache-2.0
// floatCut(): v < cut exactly when static_cast<float>(v) < threshold. Checked with the compiler's
// own double -> float rounding on the doubles next to each cut and on random doubles around it,
// for ordinary, subnormal, zero, extreme and infinite thresholds.

#include "fusedet/boost/float_cut.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <vector>

using fusedet::boosting::floatCut;

namespace {

bool roundsBelow(double v, float threshold) { return static_cast<float>(v) < threshold; }

void expectCut(float threshold) {
  const double cut = floatCut(threshold);
  const double inf = std::numeric_limits<double>::infinity();
  ASSERT_FALSE(std::isnan(cut)) << threshold;
  // The cut itself is not below; the double just under it is (unless nothing is below at all).
  EXPECT_FALSE(roundsBelow(cut, threshold)) << "threshold " << threshold << " cut " << cut;
  if (cut != -inf) {
    EXPECT_TRUE(roundsBelow(std::nextafter(cut, -inf), threshold)) << threshold;
  }
  // Doubles around the cut (a few ulps of the float on both sides), and the float values nearby.
  std::mt19937_64 rng(static_cast<std::uint64_t>(std::fabs(double(threshold))) + 17);
  const double spread = std::max(std::fabs(cut) * 1e-6, 1e-300);
  std::uniform_real_distribution<double> near(-spread, spread);
  for (int i = 0; i < 2000; ++i) {
    const double v = cut + near(rng);
    ASSERT_EQ(v < cut, roundsBelow(v, threshold)) << "threshold " << threshold << " v " << v;
  }
  float f = threshold;
  for (int k = 0; k < 4; ++k) {
    f = std::nextafter(f, -std::numeric_limits<float>::infinity());
    EXPECT_EQ(double(f) < cut, roundsBelow(double(f), threshold)) << threshold;
  }
}

}  // namespace

TEST(FloatCut, SplitsDoublesExactlyWhereRoundingToFloatDoes) {
  std::vector<float> thresholds = {0.f, -0.f, 1.f, -1.f, 0.1f, -0.1f, 1e-3f, 37.25f, 255.f, -179.99998f,
                                   3.4028235e38f, -3.4028235e38f, 1e-45f, -1e-45f, 1.17549435e-38f,
                                   std::numeric_limits<float>::infinity()};
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> anyValue(-300.f, 300.f);
  for (int i = 0; i < 500; ++i) thresholds.push_back(anyValue(rng));
  for (float t : thresholds) expectCut(t);
}

TEST(FloatCut, NothingIsBelowNanOrMinusInfinity) {
  EXPECT_TRUE(std::isnan(floatCut(std::numeric_limits<float>::quiet_NaN())));
  const double minusInf = floatCut(-std::numeric_limits<float>::infinity());
  EXPECT_EQ(minusInf, -std::numeric_limits<double>::infinity());
  EXPECT_FALSE(-1e308 < minusInf);
  // +inf: every finite float is below, and the doubles that round to +inf are not.
  const double plusInf = floatCut(std::numeric_limits<float>::infinity());
  EXPECT_TRUE(double(std::numeric_limits<float>::max()) < plusInf);
  EXPECT_FALSE(1e39 < plusInf);
  EXPECT_EQ(std::isinf(static_cast<float>(plusInf)), true);
}
