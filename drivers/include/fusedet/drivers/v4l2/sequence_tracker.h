// SPDX-License-Identifier: Apache-2.0
#pragma once
// SequenceTracker: counts frames the driver dropped, from the 32-bit sequence numbers of
// dequeued buffers. A jump forward of k means k-1 frames lost; a step back (or a repeat) means
// the driver's counter started again (stream restart, driver reset) and is counted as a reset,
// never as ~4 billion lost frames. Wrap-around at 2^32 is a normal step.

#include <cstdint>
#include <optional>

namespace fusedet::drivers::v4l2 {

class SequenceTracker {
 public:
  struct Step {
    std::uint64_t lost = 0;  // frames missing before this one
    bool reset = false;      // the counter went back: no loss can be told
  };
  Step next(std::uint32_t sequence);
  // The stream was (re)started: the next sequence number starts a new count without a gap.
  void restart() { last_.reset(); }

  std::uint64_t gaps() const { return gaps_; }      // jumps forward by more than one
  std::uint64_t lost() const { return lost_; }      // frames missing in those jumps
  std::uint64_t resets() const { return resets_; }  // unexplained steps back or repeats

 private:
  std::optional<std::uint32_t> last_;
  std::uint64_t gaps_ = 0, lost_ = 0, resets_ = 0;
};

}  // namespace fusedet::drivers::v4l2
