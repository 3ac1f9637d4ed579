// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/result.h"

#include <gtest/gtest.h>

using fusedet::Error;
using fusedet::Result;

namespace {
Result<int> parsePositive(int v) {
  if (v <= 0) return fusedet::makeError(std::errc::invalid_argument, "parse " + std::to_string(v));
  return v * 2;
}
}  // namespace

TEST(Result, ValueAndError) {
  auto ok = parsePositive(21);
  ASSERT_TRUE(ok);
  EXPECT_EQ(*ok, 42);
  auto bad = parsePositive(-1);
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code, std::errc::invalid_argument);
  EXPECT_EQ(bad.error().message(), "parse -1: Invalid argument");
  EXPECT_EQ(bad.value_or(7), 7);
}

TEST(Result, VoidAndErrno) {
  Result<void> ok;
  EXPECT_TRUE(ok);
  Result<void> bad = fusedet::errnoError(ENODEV, "open /dev/ttyUSB0");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message(), "open /dev/ttyUSB0: No such device");
}
