// SPDX-License-Identifier: Apache-2.0
#pragma once
// ScanAssembler: merges the interlaced partial scans of mode 2A into full scans. At 0.5 deg a
// full scan is 2 mirror rotations (partial index 0, 2 in 0.25 deg steps), at 0.25 deg 4 (0..3).
// Partial k' (0-based rotation) holds beams k', k'+M, k'+2M, ... of the full scan (M rotations).
// A group is emitted only when every partial arrived in order; anything else is dropped.

#include <cstdint>
#include <optional>
#include <vector>

#include "fusedet/drivers/lms291/protocol.h"

namespace fusedet::drivers::lms291 {

class ScanAssembler {
 public:
  void reset(Variant v);
  // Beams partial `rotation` carries (0-based rotation within a full scan).
  std::size_t partialSize(int rotation) const;
  // Rotation (0..M-1) of a partial-index field (0.25 deg steps), or -1 if it does not fit.
  int rotationOf(int partialIndex) const;

  // Adds one partial; returns the merged values when the group completes.
  std::optional<std::vector<std::uint16_t>> add(int partialIndex, const std::vector<std::uint16_t>& values);
  std::uint64_t droppedGroups() const { return dropped_; }

 private:
  Variant variant_;
  int next_ = 0;  // rotation expected next
  std::vector<std::uint16_t> merged_;
  std::uint64_t dropped_ = 0;
};

}  // namespace fusedet::drivers::lms291
