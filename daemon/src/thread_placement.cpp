// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/thread_placement.h"

#include <sched.h>
#include <tbb/task_arena.h>
#include <tbb/task_scheduler_observer.h>

#include <cerrno>
#include <cstring>

#include "fusedet/boost/parallel_for.h"  // FUSEDET_TSAN_LOOPS

namespace fusedet::daemon {

namespace {

// The calling thread on exactly `cpus`; 0 or the errno of the refusal.
int runOn(const std::vector<int>& cpus) {
  cpu_set_t set;
  CPU_ZERO(&set);
  for (const int c : cpus) CPU_SET(c, &set);
  return ::sched_setaffinity(0, sizeof set, &set) == 0 ? 0 : errno;
}

}  // namespace

std::vector<int> allowedCpus() {
  cpu_set_t set;
  CPU_ZERO(&set);
  std::vector<int> out;
  if (::sched_getaffinity(0, sizeof set, &set) != 0) return out;
  for (int c = 0; c < CPU_SETSIZE; ++c)
    if (CPU_ISSET(c, &set)) out.push_back(c);
  return out;
}

class DetectionPinning::Observer : public tbb::task_scheduler_observer {
 public:
  explicit Observer(const std::vector<int>& cpus) : cpus_(cpus) { observe(true); }
  ~Observer() override { observe(false); }
  void on_scheduler_entry(bool worker) override {
    if (!worker) return;  // the creating thread is pinned once, by DetectionPinning
    const int slot = tbb::this_task_arena::current_thread_index();
    if (slot < 0) return;
    runOn({cpus_[static_cast<std::size_t>(slot) % cpus_.size()]});
  }
  // TBB's workers serve every arena of the process: one that leaves ours is free again.
  void on_scheduler_exit(bool worker) override {
    if (worker) runOn(cpus_);
  }

 private:
  std::vector<int> cpus_;
};

DetectionPinning::DetectionPinning(std::vector<int> cpus) : cpus_(std::move(cpus)) {
  if (cpus_.size() < 2) {
    reason_ = cpus_.empty() ? "the kernel did not say which CPUs this thread may use" : "one CPU only";
    return;
  }
#ifdef FUSEDET_TSAN_LOOPS
  // The loops' helpers are std::threads the detection thread starts (parallel_for.h): pinned, it
  // would hand its one CPU to all of them.
  reason_ = "ThreadSanitizer build: the detection's loops run on threads of their own, not TBB's";
  return;
#endif
  if (const int e = runOn({cpus_.front()}); e != 0) {
    reason_ = std::string("sched_setaffinity: ") + std::strerror(e);
    return;
  }
  observer_ = std::make_unique<Observer>(cpus_);
}

DetectionPinning::~DetectionPinning() {
  if (!observer_) return;
  observer_.reset();
  runOn(cpus_);
}

}  // namespace fusedet::daemon
