// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/feature_pool.h"

#include <gtest/gtest.h>

#include <set>
#include <tuple>

using namespace fusedet::boosting;

namespace {
std::vector<FeatureType> types(const char* letters) { return parseFeatureTypes(letters); }
}  // namespace

// OpenCV's traincascade enumerates x2, y2, x3, y3 and x2_y2 (our a-e) on a 24x24 window into the
// well-known 162,336 Haar features; our unit-square grid of 24 must give the same count.
TEST(FeaturePool, Grid24TypesAtoEGivesOpenCvCount) {
  PoolConfig c;
  c.grid = 24;
  c.types = types("a-e");
  EXPECT_EQ(poolSize(c), 162336u);
  EXPECT_EQ(generatePool(c).size(), 162336u);
}

TEST(FeaturePool, CountsMatchGenerationAndAreUniqueAndInside) {
  PoolConfig c;
  c.grid = 10;
  c.positionStep = 2;
  c.sizeStep = 2;
  c.layers = {"intensity", "distance", "remission"};
  const auto pool = generatePool(c);
  EXPECT_EQ(pool.size(), poolSize(c));
  std::set<std::tuple<int, double, double, double, double, int>> seen;
  std::size_t perLayer[3] = {0, 0, 0};
  for (const Feature& f : pool) {
    EXPECT_NO_THROW(validateFeature(f, 3));
    const auto [gx, gy] = featureGrid(f.type);
    // Whole cells of whole grid units.
    const double cw = f.rect.w * c.grid / gx, ch = f.rect.h * c.grid / gy;
    EXPECT_NEAR(cw, std::round(cw), 1e-9);
    EXPECT_NEAR(ch, std::round(ch), 1e-9);
    EXPECT_TRUE(seen.insert({int(f.type), f.rect.x, f.rect.y, f.rect.w, f.rect.h, f.layer}).second);
    perLayer[f.layer]++;
  }
  EXPECT_EQ(perLayer[0], perLayer[1]);
  EXPECT_EQ(perLayer[1], perLayer[2]);
  std::size_t byType = 0;
  for (char t = 'a'; t <= 'j'; ++t) byType += poolSize(c, *featureTypeFromLetter(t));
  EXPECT_EQ(byType * 3, pool.size());
}

TEST(FeaturePool, HandCountedSmallGrid) {
  // grid 4, type a (2 x 1 cells): widths 2, 4 (dx = 1, 2) -> x positions 3 + 1 = 4;
  // heights 1..4 -> y positions 4 + 3 + 2 + 1 = 10; total 40. Type f (3 x 3): 2 x 2 = 4.
  PoolConfig c;
  c.grid = 4;
  c.types = types("a");
  EXPECT_EQ(poolSize(c), 40u);
  c.types = types("f");
  EXPECT_EQ(poolSize(c), 4u);
  c.types = types("af");
  c.layers = {"red", "green"};
  EXPECT_EQ(poolSize(c), 88u);
}

TEST(FeaturePool, PracticalAtHundredThousandPerLayer) {
  PoolConfig c;
  c.grid = 24;
  const std::size_t n = poolSize(c);
  EXPECT_GE(n, 100000u);
  EXPECT_EQ(generatePool(c).size(), n);
}

TEST(FeaturePool, ParsesTypeSetsAndRejectsBadInput) {
  EXPECT_EQ(types("a-c").size(), 3u);
  EXPECT_EQ(types("g-j").size(), 4u);
  EXPECT_EQ(types("jab").front(), FeatureType::kEdgeHorizontal);
  EXPECT_TRUE(types("all").empty());
  EXPECT_THROW(types("k"), std::invalid_argument);
  EXPECT_THROW(types(""), std::invalid_argument);
  PoolConfig c;
  c.layers = {"a", "a"};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.layers = {};
  EXPECT_THROW(c.validate(), std::invalid_argument);
  c.layers = {"intensity"};
  c.grid = 1;
  EXPECT_THROW(c.validate(), std::invalid_argument);
}
