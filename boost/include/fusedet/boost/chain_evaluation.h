#pragma once
// The held-back evaluation loop: running cascades over data set items and scoring them (what
// `fusedet eval`, `fusedet train --eval` and `fusedet experiments` share). A chain of several
// cascades is their AND combination (paper Tab. 7): the first one scans every window, each later
// one must also accept a window it passed, then the surviving windows are grouped into detections.

#include <cstddef>
#include <vector>

#include "fusedet/boost/box_regression.h"
#include "fusedet/boost/detection_setup.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/group_verifier.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/laser_extent.h"
#include "fusedet/boost/precision_recall.h"
#include "fusedet/core/dataset.h"

namespace fusedet::boosting {


struct EvalOutcome {
  Counts counts;
  double msPerStack = 0;  // mean wall time per stack: integral images + scan + AND + grouping
  std::vector<std::vector<Detection>> detections;  // per item
  std::vector<StackMatch> matches;                 // per item
  std::vector<FrameOutcome> frames;                // per item: scored hits and false alarms
  std::size_t windows = 0, stumps = 0;             // work done by the first cascade's scan
};

// Detections of a chain of detectors (AND) on one stack; adds the scan's work to `stats`.
std::vector<Detection> detectChain(const std::vector<const Detector*>& chain, const LayerStack& stack,
                                   const DetectionSetup& setup, ScanStats* stats = nullptr);

// The box part of what follows grouping (refineAndVerify() below adds the verifier; detectPerClass(),
// what fusedetd runs, applies the laser extent only: no model holds a fit, box_regression.h):
// the laser extent (laser_extent.h), then `regression` (identity when not fitted) on grouped
// detections. hits[k] / fates[k]: cascade k's raw hits and what became of them (grouping.h; a
// fate's `detection` indexes `detections`). `groups` (optional) gets each
// detection's GroupedBox (its box before `regression`).
void refineBoxes(std::vector<Detection>& detections, const std::vector<std::vector<RawHit>>& hits,
                 const std::vector<std::vector<HitFate>>& fates, const LayerStack& stack,
                 const LaserExtentParams& extent, const BoxRegression& regression,
                 std::vector<GroupedBox>* groups = nullptr);
// All that follows grouping, in detectChain()'s order, the one rule it and the miss analysis share:
// refineBoxes() with setup's laser extent and box regression, then setup's verifier (verifyGroups():
// may drop detections and renumbers `fates`; nothing when not fitted).
void refineAndVerify(std::vector<Detection>& detections, const std::vector<std::vector<RawHit>>& hits,
                     std::vector<std::vector<HitFate>>& fates, const LayerStack& stack, const DetectionSetup& setup);

// Detections of the chain before `setup.boxRegression` and `setup.verifier`, each with what formed
// it (box_regression.h).
std::vector<Detection> detectChainGroups(const std::vector<const Detector*>& chain, const LayerStack& stack,
                                         const DetectionSetup& setup, std::vector<GroupedBox>& groups,
                                         ScanStats* stats = nullptr);

// Fits the learned box refinement on items[indices] (a fold's TRAINING frames): each detection of
// the chain (setup without its boxRegression) whose best-overlapping positive label (match's
// rules) overlaps it by IoU >= params.minIou is a sample, its targets that label's box (the
// result's `samples` says how many were used).
BoxRegression fitBoxRefinement(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                               const std::vector<std::size_t>& indices, const MatchConfig& match,
                               const DetectionSetup& setup, const BoxFitParams& params);

// Fits the group verifier (group_verifier.h) on items[indices] (a fold's TRAINING frames): every
// detection of the chain (setup without its verifier, with its box regression) scored a hit or a
// false alarm by `match` is a sample (ignored ones are not); the items' positives count for the
// operating threshold's F.
GroupVerifier fitGroupVerification(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                                   const std::vector<std::size_t>& indices, const MatchConfig& match,
                                   const DetectionSetup& setup, const VerifierParams& params);

// Runs the chain on every item and matches against its labels.
EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const MatchConfig& match, const DetectionSetup& setup);
// The same on the items with the given indices (outcomes in that order).
EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const std::vector<std::size_t>& indices, const MatchConfig& match,
                          const DetectionSetup& setup);

}  // namespace fusedet::boosting
