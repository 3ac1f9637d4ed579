// SPDX-License-Identifier: Apache-2.0
// DetectionPinning: the creating thread and the TBB workers in its arena each on one CPU, as the
// kernel reports it (sched_getaffinity of each thread), and every CPU given back afterwards.
#include <gtest/gtest.h>
#include <sched.h>
#include <sys/syscall.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "fusedet/boost/parallel_for.h"  // FUSEDET_TSAN_LOOPS
#include "fusedet/daemon/thread_placement.h"

namespace fusedet::daemon {
namespace {

std::set<int> cpusOf(pid_t tid) {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::set<int> out;
  if (::sched_getaffinity(tid, sizeof set, &set) != 0) return out;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) out.insert(c);
  return out;
}

pid_t thisTid() {
  return static_cast<pid_t>(::syscall(SYS_gettid));
}

TEST(ThreadPlacement, AllowedCpusAreTheThreadsAffinity) {
  const std::set<int> all = cpusOf(0);
  ASSERT_FALSE(all.empty());
  const std::vector<int> listed = allowedCpus();
  EXPECT_EQ(std::set<int>(listed.begin(), listed.end()), all);
  // Narrowed as taskset would: the list follows.
  std::thread([&] {
    cpu_set_t one;
    CPU_ZERO(&one);
    CPU_SET(*all.rbegin(), &one);
    ASSERT_EQ(::sched_setaffinity(0, sizeof one, &one), 0);
    EXPECT_EQ(allowedCpus(), std::vector<int>{*all.rbegin()});
  }).join();
}

TEST(ThreadPlacement, PinsTheThreadAndEachHelperToTheirOwnCpu) {
  const std::vector<int> cpus = allowedCpus();
#ifdef FUSEDET_TSAN_LOOPS
  GTEST_SKIP() << "ThreadSanitizer build: DetectionPinning pins nothing there (thread_placement.h)";
#endif
  if (cpus.size() < 2)
    GTEST_SKIP() << "needs two CPUs (this machine lets the test use " << cpus.size() << ")";
  const std::set<int> all(cpus.begin(), cpus.end());
  struct Seen {
    pid_t tid;
    int slot;
    std::set<int> cpus;
  };
  std::vector<Seen> seen;
  pid_t caller = 0, worker = 0;
  std::set<int> callerDuring, callerAfter, workerAfter;
  // A thread of its own: its implicit arena is the one the pinning observes, as fusedetd's
  // detection thread's is.
  std::thread([&] {
    caller = thisTid();
    {
      DetectionPinning pinning(cpus);
      ASSERT_TRUE(pinning.active()) << pinning.reason();
      callerDuring = cpusOf(0);
      // Two bodies that wait for each other: a worker must run one of them.
      std::mutex m;
      std::atomic<int> started{0};
      tbb::parallel_for(0, 2, [&](int) {
        started.fetch_add(1);
        const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
        while (started.load() < 2 && std::chrono::steady_clock::now() < until) std::this_thread::yield();
        std::lock_guard lock(m);
        seen.push_back({thisTid(), tbb::this_task_arena::current_thread_index(), cpusOf(0)});
      });
      // The worker leaves the arena once it finds no work, and may then run anywhere again
      // (polled while this thread lives: its arena, and with it TBB's workers, end with it).
      for (const Seen& s : seen)
        if (s.tid != caller) worker = s.tid;
      for (int i = 0; i < 500 && worker != 0 && workerAfter != all; ++i) {
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
        workerAfter = cpusOf(worker);
      }
    }
    callerAfter = cpusOf(0);
  }).join();

  EXPECT_EQ(callerDuring, std::set<int>{cpus[0]});
  EXPECT_EQ(callerAfter, all);
  ASSERT_EQ(seen.size(), 2u);
  EXPECT_NE(seen[0].tid, seen[1].tid) << "both bodies ran on one thread: no worker joined in 10 s";
  for (const Seen& s : seen) {
    ASSERT_GE(s.slot, 0);
    EXPECT_EQ(s.cpus, std::set<int>{cpus[static_cast<std::size_t>(s.slot) % cpus.size()]})
        << "thread " << s.tid << " in slot " << s.slot;
    if (s.tid == caller) {
      EXPECT_EQ(s.slot, 0);
    }
  }
  ASSERT_NE(worker, 0);
  EXPECT_EQ(workerAfter, all) << "worker " << worker << " still pinned 5 s after the loop";
}

TEST(ThreadPlacement, PinsNothingWithoutTwoCpusOrWhenTheKernelRefuses) {
  const std::set<int> before = cpusOf(0);
  {
    DetectionPinning none(std::vector<int>{});
    EXPECT_FALSE(none.active());
    EXPECT_NE(none.reason().find("did not say"), std::string::npos) << none.reason();
    DetectionPinning one(std::vector<int>{*before.begin()});
    EXPECT_FALSE(one.active());
    EXPECT_EQ(one.reason(), "one CPU only");
    // CPUs the machine does not have: sched_setaffinity refuses (EINVAL), as a seccomp filter
    // would (EPERM).
    DetectionPinning absent(std::vector<int>{CPU_SETSIZE - 2, CPU_SETSIZE - 1});
    EXPECT_FALSE(absent.active());
#ifndef FUSEDET_TSAN_LOOPS
    EXPECT_NE(absent.reason().find("sched_setaffinity: "), std::string::npos) << absent.reason();
#endif
  }
  EXPECT_EQ(cpusOf(0), before);
}

}  // namespace
}  // namespace fusedet::daemon
