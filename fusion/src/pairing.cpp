// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/pairing.h"

#include <cstdlib>
#include <stdexcept>

namespace fusedet::fusion {

FramePairer::FramePairer(std::int64_t maxSkewNs, std::size_t capacity, std::size_t maxBytes)
    : maxSkewNs_(maxSkewNs), capacity_(capacity), maxBytes_(maxBytes) {
  if (maxSkewNs < 0 || capacity == 0) throw std::invalid_argument("FramePairer: skew must be >= 0, capacity > 0");
}

void FramePairer::addFrame(drivers::CameraFrame frame) {
  bytes_ += frame.bytes.size();
  frames_.push_back(std::move(frame));
  while (frames_.size() > capacity_ || (frames_.size() > 1 && bytes_ > maxBytes_)) {
    bytes_ -= frames_.front().bytes.size();
    frames_.pop_front();
    ++dropped_;
  }
}

std::optional<drivers::CameraFrame> FramePairer::pair(const Sweep& sweep) {
  const Stamp middle = sweep.middle();
  std::size_t best = frames_.size();
  std::int64_t bestSkew = 0;
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    const std::int64_t skew = std::llabs(frames_[i].stamp - middle);
    if (best == frames_.size() || skew < bestSkew) {
      best = i;
      bestSkew = skew;
    }
  }
  if (best == frames_.size() || bestSkew > maxSkewNs_) {
    ++unpaired_;
    return std::nullopt;
  }
  drivers::CameraFrame out = std::move(frames_[best]);
  for (std::size_t i = 0; i <= best; ++i) bytes_ -= i == best ? out.bytes.size() : frames_[i].bytes.size();
  frames_.erase(frames_.begin(), frames_.begin() + static_cast<std::ptrdiff_t>(best) + 1);
  return out;
}

}  // namespace fusedet::fusion
