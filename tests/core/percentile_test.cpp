// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/percentile.h"

#include <gtest/gtest.h>

#include <vector>

namespace {

using fusedet::percentile;

TEST(Percentile, NearestRankOfUnsortedValues) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);
  EXPECT_DOUBLE_EQ(percentile(v, 0.5), 50);
  EXPECT_DOUBLE_EQ(percentile(v, 0.99), 99);
  EXPECT_DOUBLE_EQ(percentile(v, 1.0), 100);
  EXPECT_DOUBLE_EQ(percentile(v, 0.0), 1);
  // Ten values: p90 is the 9th, p99 already the largest (rank ceil(9.9) = 10), p50 the 5th.
  const std::vector<double> ten = {7, 3, 10, 1, 9, 2, 8, 4, 6, 5};
  EXPECT_DOUBLE_EQ(percentile(ten, 0.9), 9);
  EXPECT_DOUBLE_EQ(percentile(ten, 0.99), 10);
  EXPECT_DOUBLE_EQ(percentile(ten, 0.5), 5);
  EXPECT_DOUBLE_EQ(percentile(ten, 0.51), 6);
}

TEST(Percentile, NoValuesGiveZeroAndOneValueIsEveryPercentile) {
  EXPECT_DOUBLE_EQ(percentile({}, 0.5), 0);
  EXPECT_DOUBLE_EQ(percentile({4.5}, 0.01), 4.5);
  EXPECT_DOUBLE_EQ(percentile({4.5}, 1.0), 4.5);
}

}  // namespace
