// SPDX-License-Identifier: Apache-2.0
#pragma once
// Tracks measured on a KITTI tracking sequence, per class: CLEAR MOT and HOTA of the confirmed
// tracks, and detection recall / precision / F of every detection against only the detections
// that belong to a confirmed track (does tracking remove false alarms?). Which labels count and
// which detections are ignored is boost/class_rules.h (matchConfigFor: KITTI moderate, Van the
// ignored neighbour of car, DontCare absorbs), at IoU 0.5 for every class as the KITTI tracking
// benchmark scores; a detection the rules ignore is no hypothesis for the MOT metrics either.
// Library `fusedet_tracking_eval` (it needs boost/'s evaluation; the tracker does not).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/core/label.h"
#include "fusedet/tracking/clear_mot.h"
#include "fusedet/tracking/hota.h"

namespace fusedet::tracking {

// The IoU a detection needs to hit a label in the KITTI tracking benchmark (every class).
inline constexpr double kKittiTrackingMinIou = 0.5;

struct TrackedDetection {
  std::string className;
  Box box;
  double score = 0;
  std::optional<std::uint64_t> track;  // none: not tracked (no laser position)
  bool confirmed = false;
};

struct TrackedFrame {
  Labels labels;                   // the frame's KITTI labels (label_2, project classes)
  std::vector<int> labelTracks;    // per label its KITTI track id (-1: none, e.g. DontCare)
  std::vector<TrackedDetection> detections;
};

struct ClassTracking {
  std::string className;
  std::size_t frames = 0;
  ClearMot clear;
  ClearMotTimeline timeline;   // per frame, what happened to each truth object (clear_mot.h)
  Hota hota;
  boosting::Counts raw;        // every detection of the class
  boosting::Counts confirmed;  // only those of confirmed tracks
};

// Throws std::invalid_argument when a frame's labelTracks does not have one entry per label.
ClassTracking evaluateTracking(const std::vector<TrackedFrame>& frames, const std::string& className);

// Which synthesised stroke (one KITTI frame each) a sweep belongs to: the last stroke that
// started at or before the sweep's middle; -1 before the first. strokeStartsNs ascending (the
// log's fusedet.recording stroke_starts_ns).
int strokeOfSweep(const std::vector<std::int64_t>& strokeStartsNs, std::int64_t sweepStartNs, std::int64_t sweepEndNs);

}  // namespace fusedet::tracking
