// SPDX-License-Identifier: Apache-2.0
#pragma once
// Ranking measures over many frames: the precision-recall curve over the detections' scores and
// average precision (AP), as the KITTI object devkit computes them.
//
// Detections of all frames are pooled and ranked by score (a threshold = a distinct score: tied
// detections enter together). Because matching is greedy by descending score (evaluation.h), the
// outcomes at a threshold are those of the one matching pass. The curve ends at the detector's
// operating point (its lowest score), so recall never reaches what the detector did not output.
//
// AP interpolation: p_interp(r) = the highest precision at any recall >= r (0 when none).
//  - kKitti40 (KITTI since 2019): the mean of p_interp at r = 1/40, 2/40, ..., 40/40;
//  - kPascal11 (KITTI before 2019, PASCAL VOC 2007): the mean at r = 0, 0.1, ..., 1.0.

#include <cstddef>
#include <optional>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/core/detection.h"

namespace fusedet::boosting {

// One frame's detections that counted (hits and false alarms; ignored ones are dropped) with their
// scores, and the frame's positives.
struct FrameOutcome {
  struct Scored {
    double score = 0;
    bool hit = false;
  };
  std::vector<Scored> detections;
  std::size_t positives = 0;
};
FrameOutcome frameOutcome(const std::vector<Detection>& detections, const StackMatch& match);

// Counts at the operating point (every detection output) of a set of frames.
Counts countsOf(const std::vector<const FrameOutcome*>& frames);

struct PrPoint {
  double threshold = 0;  // detections with score >= threshold
  std::size_t hits = 0, falseAlarms = 0;
  double recall = 0, precision = 0;
};

// One point per distinct score, highest threshold first. Empty when no detection counted.
// `positives` = 0 gives recall 0 everywhere.
std::vector<PrPoint> precisionRecallCurve(const std::vector<const FrameOutcome*>& frames);

enum class ApRule { kKitti40, kPascal11 };
// Undefined (nullopt) without positives; 0 when there are positives but no detections.
std::optional<double> averagePrecision(const std::vector<PrPoint>& curve, std::size_t positives,
                                       ApRule rule = ApRule::kKitti40);
std::optional<double> averagePrecision(const std::vector<const FrameOutcome*>& frames,
                                       ApRule rule = ApRule::kKitti40);

// Pointers to every frame of a vector (the measures above take subsets and resamples).
std::vector<const FrameOutcome*> allFrames(const std::vector<FrameOutcome>& frames);

}  // namespace fusedet::boosting
