// SPDX-License-Identifier: Apache-2.0
#pragma once
// BufferRing: which mmap buffers the kernel holds (queued) and which the application holds, as
// pure bookkeeping. V4l2Camera checks every VIDIOC_DQBUF answer against it, so a driver that
// returns an unknown index, a buffer it was never given, or more bytes than the buffer holds is
// caught and counted instead of reading out of bounds.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "fusedet/core/result.h"

namespace fusedet::drivers::v4l2 {

constexpr std::uint32_t kMinBuffers = 4;  // fewer and a short scheduling delay drops frames

// Error (not_enough_memory) when the device granted fewer
// than kMinBuffers (or none) of the `requested`; names the device and both counts.
Result<void> checkGrantedBuffers(const std::string& device, std::uint32_t requested, std::uint32_t granted);

class BufferRing {
 public:
  // `count` buffers, all held by the application, lengths unknown (0) until setLength().
  void reset(std::uint32_t count);
  void setLength(std::uint32_t index, std::size_t length);
  std::uint32_t size() const { return static_cast<std::uint32_t>(slots_.size()); }
  std::size_t length(std::uint32_t index) const { return slots_.at(index).length; }
  bool isQueued(std::uint32_t index) const { return slots_.at(index).queued; }
  std::uint32_t queued() const { return queued_; }

  // Errors (protocol_error) say what is inconsistent; the state is unchanged then.
  Result<void> markQueued(std::uint32_t index);
  Result<void> markDequeued(std::uint32_t index, std::uint32_t bytesUsed);
  void markAllDequeued();  // VIDIOC_STREAMOFF hands every buffer back

 private:
  struct Slot {
    std::size_t length = 0;
    bool queued = false;
  };
  std::vector<Slot> slots_;
  std::uint32_t queued_ = 0;
};

}  // namespace fusedet::drivers::v4l2
