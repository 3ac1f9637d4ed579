// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/buffer_ring.h"

namespace fusedet::drivers::v4l2 {

Result<void> checkGrantedBuffers(const std::string& device, std::uint32_t requested, std::uint32_t granted) {
  if (granted >= kMinBuffers) return {};
  return makeError(std::errc::not_enough_memory, "camera " + device + ": asked for " + std::to_string(requested) +
                                                     " capture buffers, the device granted " + std::to_string(granted) +
                                                     " (need at least " + std::to_string(kMinBuffers) + ")");
}

void BufferRing::reset(std::uint32_t count) {
  slots_.assign(count, Slot{});
  queued_ = 0;
}

void BufferRing::setLength(std::uint32_t index, std::size_t length) { slots_.at(index).length = length; }

Result<void> BufferRing::markQueued(std::uint32_t index) {
  if (index >= slots_.size())
    return makeError(std::errc::protocol_error, "buffer " + std::to_string(index) + " does not exist (" +
                                                    std::to_string(slots_.size()) + " buffers)");
  if (slots_[index].queued)
    return makeError(std::errc::protocol_error, "buffer " + std::to_string(index) + " is already queued");
  slots_[index].queued = true;
  ++queued_;
  return {};
}

Result<void> BufferRing::markDequeued(std::uint32_t index, std::uint32_t bytesUsed) {
  if (index >= slots_.size())
    return makeError(std::errc::protocol_error, "the driver returned buffer " + std::to_string(index) + " of " +
                                                    std::to_string(slots_.size()));
  Slot& s = slots_[index];
  if (!s.queued)
    return makeError(std::errc::protocol_error, "the driver returned buffer " + std::to_string(index) + ", which was not queued");
  if (bytesUsed > s.length)
    return makeError(std::errc::protocol_error, "buffer " + std::to_string(index) + " reports " + std::to_string(bytesUsed) +
                                                    " bytes used of " + std::to_string(s.length));
  s.queued = false;
  --queued_;
  return {};
}

void BufferRing::markAllDequeued() {
  for (Slot& s : slots_) s.queued = false;
  queued_ = 0;
}

}  // namespace fusedet::drivers::v4l2
