// SPDX-License-Identifier: Apache-2.0
// parallelFor / parallelForEach (the detector's and the trainer's loops): every index exactly
// once, no more threads than the enclosing arena allows, a body's exception reaches the caller.
// The suite runs TBB's loops; `scripts/sanitize tsan` runs this program too, with the loops on
// std::threads (fusedet/boost/parallel_for.h says why).

#include "fusedet/boost/parallel_for.h"

#include <gtest/gtest.h>

#include <mutex>
#include <set>
#include <stdexcept>
#include <thread>
#include <vector>

using namespace fusedet::boosting;

namespace {

// How often each index of [0, n) was visited by parallelFor over a range of that grain.
std::vector<int> visits(std::size_t n, std::size_t grain) {
  std::vector<int> seen(n, 0);
  parallelFor(tbb::blocked_range<std::size_t>(0, n, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    EXPECT_LT(r.begin(), r.end());
    for (std::size_t i = r.begin(); i != r.end(); ++i) ++seen[i];
  });
  return seen;
}

}  // namespace

TEST(ParallelFor, EveryIndexExactlyOnce) {
  for (std::size_t n : {0, 1, 2, 3, 7, 64, 1000, 4099})
    for (std::size_t grain : {1, 3, 16, 5000}) {
      const std::vector<int> seen = visits(n, grain);
      ASSERT_EQ(seen.size(), n);
      for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(seen[i], 1) << "index " << i << " of " << n << ", grain " << grain;
    }
}

TEST(ParallelFor, SignedRangeAndIndexForm) {
  std::vector<int> seen(50, 0);
  parallelFor(tbb::blocked_range<int>(-20, 30), [&](const tbb::blocked_range<int>& r) {
    for (int i = r.begin(); i != r.end(); ++i) ++seen[static_cast<std::size_t>(i + 20)];
  });
  for (int v : seen) EXPECT_EQ(v, 1);
  std::vector<int> each(333, 0);
  parallelForEach(std::size_t(0), each.size(), [&](std::size_t i) { each[i] += static_cast<int>(i) + 1; });
  parallelForEach(
      std::size_t(0), each.size(), [&](std::size_t i) { each[i] *= 2; }, tbb::simple_partitioner());
  for (std::size_t i = 0; i < each.size(); ++i) EXPECT_EQ(each[i], 2 * (static_cast<int>(i) + 1));
  parallelForEach(5, 5, [](int) { ADD_FAILURE() << "an empty range runs no body"; });
}

TEST(ParallelFor, NoMoreThreadsThanTheArena) {
  std::mutex m;
  std::set<std::thread::id> ran;
  tbb::task_arena one(1);
  one.execute([&] {
    parallelFor(tbb::blocked_range<std::size_t>(0, 200), [&](const tbb::blocked_range<std::size_t>&) {
      std::lock_guard<std::mutex> lock(m);
      ran.insert(std::this_thread::get_id());
    });
  });
  EXPECT_EQ(ran.size(), 1u);
  ran.clear();
  tbb::task_arena two(2);
  two.execute([&] {
    parallelForEach(0, 200, [&](int) {
      std::lock_guard<std::mutex> lock(m);
      ran.insert(std::this_thread::get_id());
    });
  });
  EXPECT_GE(ran.size(), 1u);
  EXPECT_LE(ran.size(), 2u);
}

TEST(ParallelFor, ABodysExceptionReachesTheCaller) {
  EXPECT_THROW(parallelFor(tbb::blocked_range<std::size_t>(0, 100),
                           [](const tbb::blocked_range<std::size_t>& r) {
                             for (std::size_t i = r.begin(); i != r.end(); ++i)
                               if (i == 73) throw std::runtime_error("index 73");
                           }),
               std::runtime_error);
  EXPECT_THROW(parallelForEach(0, 10, [](int i) {
                 if (i == 9) throw std::invalid_argument("index 9");
               }),
               std::invalid_argument);
}
