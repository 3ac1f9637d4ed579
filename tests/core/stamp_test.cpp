#include "fusedet/core/stamp.h"

#include <gtest/gtest.h>
#include <time.h>

using fusedet::Stamp;

TEST(Stamp, NowIsMonotonicAndMatchesClock) {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  const std::int64_t before = std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
  const Stamp a = Stamp::now();
  const Stamp b = Stamp::now();
  EXPECT_GE(a.ns, before);
  EXPECT_LE(a, b);
  EXPECT_LT(a.ns - before, 1'000'000'000);  // same clock, not CLOCK_REALTIME
}

TEST(Stamp, ArithmeticAndFormatting) {
  const Stamp s{1'500'000'001};
  EXPECT_EQ((s + 999'999'999).ns, 2'500'000'000);
  EXPECT_EQ(Stamp{2'000'000'000} - s, 499'999'999);
  EXPECT_DOUBLE_EQ(Stamp::fromSeconds(0.25).seconds(), 0.25);
  EXPECT_EQ(s.toString(), "1.500000001");
  EXPECT_EQ(Stamp{-250'000'000}.toString(), "-0.250000000");
}
