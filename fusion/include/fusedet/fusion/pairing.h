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
  // maxSkewNs: largest |frame stamp - sweep middle| accepted; capacity: frames kept (oldest go).
  explicit FramePairer(std::int64_t maxSkewNs, std::size_t capacity = 32);

  void addFrame(drivers::CameraFrame frame);
  // The buffered frame nearest to sweep.middle() (ties: the earlier one) if within the skew,
  // else nothing (counted in unpaired()). Frames older than the chosen one are discarded.
  std::optional<drivers::CameraFrame> pair(const Sweep& sweep);

  std::size_t buffered() const { return frames_.size(); }
  std::uint64_t unpaired() const { return unpaired_; }
  std::uint64_t framesDropped() const { return dropped_; }

 private:
  std::int64_t maxSkewNs_;
  std::size_t capacity_;
  std::deque<drivers::CameraFrame> frames_;
  std::uint64_t unpaired_ = 0, dropped_ = 0;
};

}  // namespace fusedet::fusion
