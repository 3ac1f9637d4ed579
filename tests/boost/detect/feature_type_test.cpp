// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/feature_type.h"

#include <gtest/gtest.h>

using namespace fusedet::boosting;

TEST(FeatureType, LettersRoundTripAndCornersAreGtoJ) {
  int corners = 0;
  for (char c = 'a'; c <= 'j'; ++c) {
    const auto t = featureTypeFromLetter(c);
    ASSERT_TRUE(t.has_value()) << c;
    EXPECT_EQ(toLetter(*t), c);
    corners += isCorner(*t);
    EXPECT_FALSE(toName(*t).empty());
  }
  EXPECT_EQ(corners, 4);
  EXPECT_FALSE(featureTypeFromLetter('k').has_value());
  EXPECT_FALSE(featureTypeFromLetter('A').has_value());
  EXPECT_TRUE(isCorner(*featureTypeFromLetter('g')));
  EXPECT_FALSE(isCorner(*featureTypeFromLetter('f')));
}
