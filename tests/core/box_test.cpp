// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/box.h"

#include <gtest/gtest.h>

using fusedet::Box;

TEST(Box, IouOfOverlappingBoxes) {
  const Box a{0, 0, 10, 10}, b{5, 0, 10, 10};
  // intersection 5x10 = 50, union 150
  EXPECT_DOUBLE_EQ(fusedet::intersectionArea(a, b), 50.0);
  EXPECT_DOUBLE_EQ(fusedet::iou(a, b), 50.0 / 150.0);
  EXPECT_DOUBLE_EQ(fusedet::iou(a, a), 1.0);
}

TEST(Box, DisjointTouchingAndEmpty) {
  EXPECT_EQ(fusedet::iou(Box{0, 0, 1, 1}, Box{1, 0, 1, 1}), 0.0);  // touching edge
  EXPECT_EQ(fusedet::iou(Box{0, 0, 0, 0}, Box{0, 0, 0, 0}), 0.0);
  EXPECT_EQ((Box{0, 0, -2, 3}.area()), 0.0);
}

TEST(Box, CoverageIsAsymmetric) {
  const Box small{2, 2, 2, 2}, big{0, 0, 10, 10};
  EXPECT_DOUBLE_EQ(fusedet::coverage(small, big), 1.0);
  EXPECT_DOUBLE_EQ(fusedet::coverage(big, small), 0.04);
}
