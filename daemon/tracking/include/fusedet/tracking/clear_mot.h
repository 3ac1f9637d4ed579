// SPDX-License-Identifier: Apache-2.0
#pragma once
// CLEAR MOT (Bernardin & Stiefelhagen 2008) as TrackEval computes it: per frame a truth object
// and a hypothesis match when their IoU >= minIou; the pairs matched in the previous frame are
// kept when still above the threshold (they win the assignment), the rest by an optimal
// assignment maximising summed IoU. An id switch is a matched truth whose hypothesis id differs
// from the one it was last matched to (in any earlier frame). A fragmentation is every
// interruption of a truth trajectory's matched frames that is followed by a match again.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include "fusedet/tracking/mot_sequence.h"

namespace fusedet::tracking {

struct ClearMot {
  std::size_t truth = 0, hypotheses = 0;              // objects summed over frames
  std::size_t matches = 0, misses = 0, falsePositives = 0;
  std::size_t idSwitches = 0, fragmentations = 0;
  std::size_t trajectories = 0;                       // distinct truth ids
  std::size_t mostlyTracked = 0, partiallyTracked = 0, mostlyLost = 0;  // matched in > 80 %, else, < 20 % of its frames
  double iouSum = 0;                                  // over matches

  // 1 - (misses + false positives + id switches) / truth; nothing when there is no truth.
  double mota() const;
  // Mean IoU of the matches (0 without matches).
  double motp() const;
};

// What happened to each truth object in each frame (for pictures of tracks over time).
struct TruthEvent {
  std::int64_t truth = 0;
  std::optional<std::int64_t> hypothesis;  // matched hypothesis id; none = missed
  bool idSwitch = false;                   // matched to another hypothesis than last time
  bool resumed = false;                    // matched again after an interruption (a fragmentation)
};
using ClearMotTimeline = std::vector<std::vector<TruthEvent>>;  // per frame, per truth object

// `timeline`, when given, receives one entry per frame.
ClearMot clearMot(const MotSequence& sequence, double minIou = 0.5, ClearMotTimeline* timeline = nullptr);

}  // namespace fusedet::tracking
