// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/stamp.h"

#include "fusedet/core/cpu_time.h"

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

// The CPU clocks are the kernel's: compared with clock_gettime read here, and they advance with
// work done on this thread while sleeping adds (almost) nothing.
TEST(CpuTime, ClocksFollowTheKernelsThreadAndProcessClocks) {
  auto kernelMs = [](clockid_t id) {
    timespec t{};
    clock_gettime(id, &t);
    return double(t.tv_sec) * 1e3 + double(t.tv_nsec) * 1e-6;
  };
  // Read before t0 so the process clock's window holds the thread clock's whole window: read after
  // it, the few microseconds between the two reads may be missing from the process delta.
  const double pBefore = fusedet::processCpuMs();
  const double k0 = kernelMs(CLOCK_THREAD_CPUTIME_ID);
  const double t0 = fusedet::threadCpuMs();
  const double p0 = fusedet::processCpuMs();
  EXPECT_GE(t0, k0);
  EXPECT_LT(t0 - k0, 50.0);
  EXPECT_GE(p0, t0);  // the process clock includes this thread's time
  volatile double sink = 0;
  while (fusedet::threadCpuMs() - t0 < 20.0) sink = sink + 1.0;  // burn ~20 ms of this thread's CPU
  const double t1 = fusedet::threadCpuMs();
  EXPECT_GE(t1 - t0, 20.0);
  EXPECT_GE(fusedet::processCpuMs() - pBefore, t1 - t0);
  EXPECT_LE(t1, kernelMs(CLOCK_THREAD_CPUTIME_ID));
  const double beforeSleep = fusedet::threadCpuMs();
  timespec nap{0, 30'000'000};
  nanosleep(&nap, nullptr);
  EXPECT_LT(fusedet::threadCpuMs() - beforeSleep, 15.0);  // 30 ms asleep is not CPU time
}
