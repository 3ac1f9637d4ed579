// SPDX-License-Identifier: Apache-2.0
#pragma once
// Thread names and CPU times: the daemon's threads carry names (visible in `top -H`, `ps -L`,
// perf) and its stage timings report CPU time beside wall time, since on a shared machine wall
// time also counts waiting for a core (the calling thread's CPU clock: core/cpu_time.h threadCpuMs()).

#include <memory>
#include <string>
#include <vector>

namespace fusedet::daemon {

// Names the calling thread (Linux keeps the first 15 characters).
void nameThisThread(const std::string& name);

// While it lives, TBB's worker threads that work in the creating thread's arena (the detection
// scan's helpers) are named `name`; they would otherwise carry the name of whichever thread
// first started TBB work.
class TbbWorkerNames {
 public:
  explicit TbbWorkerNames(std::string name);
  ~TbbWorkerNames();
  TbbWorkerNames(const TbbWorkerNames&) = delete;
  TbbWorkerNames& operator=(const TbbWorkerNames&) = delete;

 private:
  class Observer;
  std::unique_ptr<Observer> observer_;
};

struct ThreadCpu {
  int tid = 0;
  std::string name;
  double cpuMs = 0;  // user + system time so far
};
// Every thread of this process (/proc/self/task), in tid order; empty if /proc is unreadable.
std::vector<ThreadCpu> processThreadCpu();

}  // namespace fusedet::daemon
