// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/scan_assembler.h"

namespace fusedet::drivers::lms291 {

void ScanAssembler::reset(Variant v) {
  variant_ = v;
  next_ = 0;
  merged_.assign(static_cast<std::size_t>(v.beams()), 0);
}

std::size_t ScanAssembler::partialSize(int rotation) const {
  const int m = variant_.rotations();
  const int n = variant_.beams();
  return static_cast<std::size_t>((n - rotation + m - 1) / m);
}

int ScanAssembler::rotationOf(int partialIndex) const {
  const int stepsPerBeam = variant_.resolutionCdeg / 25;  // partial index counts 0.25 deg
  if (partialIndex % stepsPerBeam != 0) return -1;
  const int r = partialIndex / stepsPerBeam;
  return r < variant_.rotations() ? r : -1;
}

std::optional<std::vector<std::uint16_t>> ScanAssembler::add(int partialIndex,
                                                              const std::vector<std::uint16_t>& values) {
  const int rotation = rotationOf(partialIndex);
  const bool fits = rotation >= 0 && values.size() == partialSize(rotation);
  if (fits && rotation == 0) {
    if (next_ > 0) ++dropped_;  // the group in progress never completed
  } else if (!fits || rotation != next_) {
    // A partial went missing or is malformed: the group is lost; wait for the next rotation 0.
    if (next_ >= 0) ++dropped_;
    next_ = -1;
    return std::nullopt;
  }
  const int m = variant_.rotations();
  for (std::size_t j = 0; j < values.size(); ++j) merged_[static_cast<std::size_t>(rotation) + j * m] = values[j];
  next_ = rotation + 1;
  if (next_ < m) return std::nullopt;
  next_ = 0;
  return merged_;
}

}  // namespace fusedet::drivers::lms291
