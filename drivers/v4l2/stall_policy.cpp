// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/stall_policy.h"

namespace fusedet::drivers::v4l2 {

void StallPolicy::streamStarted(Clock::time_point now) { since_ = now; }

void StallPolicy::frameArrived(Clock::time_point now) {
  since_ = now;
  restarts_ = 0;
}

StallAction StallPolicy::check(Clock::time_point now) {
  if (now - since_ < limit_) return StallAction::kNone;
  ++stalls_;
  since_ = now;  // the next action only after another full limit
  if (restarts_ < maxRestarts_) {
    ++restarts_;
    return StallAction::kRestartStream;
  }
  restarts_ = 0;
  return StallAction::kReopen;
}

}  // namespace fusedet::drivers::v4l2
