// SPDX-License-Identifier: Apache-2.0
#pragma once
// Thread placement of the detection: the detection thread and each TBB helper that works in its
// arena on a CPU of its own.
//
// Why: left to the kernel, the scan's helper, woken at the start of a parallel loop, was often
// put on the detection thread's CPU while the other CPU idled, and the two shared that CPU in
// 4 ms slices until the load balancer moved one (2-core VMs: a sched_switch trace of
// bench_daemon_latency showed 43 of fd-detect's 58 preemptions in 12 stacks were by its own
// helper with the other CPU idle; bench/README.md, "detection threads pinned").

#include <memory>
#include <string>
#include <vector>

namespace fusedet::daemon {

// The CPUs the calling thread may run on (sched_getaffinity: taskset, cpusets, systemd's
// CPUAffinity=), ascending; empty if the kernel does not say.
std::vector<int> allowedCpus();

// While it lives: the creating thread runs on cpus[0], and a TBB worker that enters the creating
// thread's arena runs on cpus[slot % cpus.size()] (slot: its index in that arena, the creating
// thread's being 0) until it leaves the arena, when it may run on every CPU of `cpus` again.
// Destroyed (in the creating thread), it gives that thread every CPU of `cpus` back. With fewer
// than two CPUs, where the kernel refuses (e.g. a seccomp filter: EPERM) and in ThreadSanitizer
// builds (their loops run on std::threads, boost/.../parallel_for.h) it pins nothing and says why
// in reason().
class DetectionPinning {
 public:
  explicit DetectionPinning(std::vector<int> cpus = allowedCpus());
  ~DetectionPinning();
  DetectionPinning(const DetectionPinning&) = delete;
  DetectionPinning& operator=(const DetectionPinning&) = delete;

  bool active() const { return observer_ != nullptr; }
  const std::vector<int>& cpus() const { return cpus_; }
  const std::string& reason() const { return reason_; }  // why not active

 private:
  class Observer;
  std::vector<int> cpus_;
  std::string reason_;
  std::unique_ptr<Observer> observer_;
};

}  // namespace fusedet::daemon
