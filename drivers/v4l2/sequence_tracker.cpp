// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/sequence_tracker.h"

namespace fusedet::drivers::v4l2 {

SequenceTracker::Step SequenceTracker::next(std::uint32_t sequence) {
  Step step;
  if (last_) {
    const std::uint32_t diff = sequence - *last_;  // modulo 2^32: wrap-around is a step of 1
    if (diff == 0 || diff > 0x8000'0000u) {
      step.reset = true;
      ++resets_;
    } else if (diff > 1) {
      step.lost = diff - 1;
      ++gaps_;
      lost_ += step.lost;
    }
  }
  last_ = sequence;
  return step;
}

}  // namespace fusedet::drivers::v4l2
