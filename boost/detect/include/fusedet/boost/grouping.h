// SPDX-License-Identifier: Apache-2.0
#pragma once
// From raw window hits to detections by cv::groupRectangles' rule: hits whose four edges lie within
// eps * mean(min width, min height) / 2 of each other are linked, linked sets form groups
// (transitively), a group becomes its average rectangle if it has more than minNeighbors members,
// and groups that sit inside a bigger, better supported group are dropped. Score = members in the
// group. minNeighbors <= 0 returns every hit unchanged (OpenCV's behaviour). Output order is
// deterministic: groups by their first hit.

#include <span>
#include <string>
#include <vector>

#include "fusedet/boost/detector.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

struct GroupParams {
  int minNeighbors = 3;
  double eps = 0.2;  // OpenCV's GROUP_EPS
};

// What became of one raw hit (miss_analysis.h asks): the detection it went into, or why none.
struct HitFate {
  enum class Outcome {
    kKept,               // part of a group that became output detection `detection`
    kTooFewNeighbours,   // its group had <= minNeighbors members
    kInsideBiggerGroup,  // its group lay inside a bigger, better supported one
  };
  Outcome outcome = Outcome::kKept;
  int detection = -1;  // index into groupHits()' output, -1 when the hit went into none
  int groupSize = 1;   // members of its group
};

// Detections for `className` in `stack` (boxes in its reference pixels, unitBox, stamp, stackId).
// `fates` (optional) gets one entry per hit; the detections are the same with or without it.
std::vector<Detection> groupHits(std::span<const RawHit> hits, const GroupParams& params,
                                 const std::string& className, const LayerStack& stack,
                                 std::vector<HitFate>* fates = nullptr);

// Scan + group in one call.
std::vector<Detection> detect(const Detector& detector, const LayerStack& stack, const ScanParams& scan,
                              const GroupParams& group);

}  // namespace fusedet::boosting
