// SPDX-License-Identifier: Apache-2.0
#pragma once
// Pairing of a sweep with the camera frame nearest to the sweep's middle (design §4), within a
// configured skew; frames wait in a small buffer until their sweep is complete.

#include <cstdint>
#include <deque>
#include <optional>

#include "fusedet/drivers/messages.h"
#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

class FramePairer {
 public:
  // maxSkewNs: largest |frame stamp - sweep middle| accepted; capacity: frames kept (oldest go),
  // also while their bytes exceed maxBytes (the newest frame always stays): 32 1080p frames
  // would be 200 MB.
  explicit FramePairer(std::int64_t maxSkewNs, std::size_t capacity = 32, std::size_t maxBytes = 64u << 20);

  void addFrame(drivers::CameraFrame frame);
  // The buffered frame nearest to sweep.middle() (ties: the earlier one) if within the skew,
  // else nothing (counted in unpaired()). Frames older than the chosen one are discarded.
  std::optional<drivers::CameraFrame> pair(const Sweep& sweep);

  std::size_t buffered() const { return frames_.size(); }
  std::size_t bufferedBytes() const { return bytes_; }
  std::uint64_t unpaired() const { return unpaired_; }
  std::uint64_t framesDropped() const { return dropped_; }

 private:
  std::int64_t maxSkewNs_;
  std::size_t capacity_;
  std::size_t maxBytes_;
  std::size_t bytes_ = 0;  // of the frames kept
  std::deque<drivers::CameraFrame> frames_;
  std::uint64_t unpaired_ = 0, dropped_ = 0;
};

}  // namespace fusedet::fusion
