// SPDX-License-Identifier: Apache-2.0
#pragma once
// StallPolicy: decides, from frame arrival times alone, when a stream has stalled and what to do:
// restart the stream (STREAMOFF/STREAMON on the open device) up to `maxRestarts` times in a row,
// then reopen the device. Pure logic on caller-supplied time points, so tests need no clock.

#include <chrono>
#include <cstdint>

namespace fusedet::drivers::v4l2 {

enum class StallAction { kNone, kRestartStream, kReopen };

class StallPolicy {
 public:
  using Clock = std::chrono::steady_clock;
  StallPolicy(std::chrono::milliseconds limit, int maxRestarts) : limit_(limit), maxRestarts_(maxRestarts) {}

  void streamStarted(Clock::time_point now);  // fresh device: the limit counts from here
  void frameArrived(Clock::time_point now);   // resets the escalation
  // kNone until `limit` passes without a frame; then one action per expired limit. The caller
  // reports the action done with streamStarted() (restart) or a new streamStarted() after reopen.
  StallAction check(Clock::time_point now);

  std::uint64_t stalls() const { return stalls_; }
  int restartsInARow() const { return restarts_; }

 private:
  std::chrono::milliseconds limit_;
  int maxRestarts_;
  Clock::time_point since_{};
  int restarts_ = 0;
  std::uint64_t stalls_ = 0;
};

}  // namespace fusedet::drivers::v4l2
