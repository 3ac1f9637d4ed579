// SPDX-License-Identifier: Apache-2.0
#pragma once
// The held-back evaluation loop: running cascades over data set items and scoring them (what
// `fusedet eval`, `fusedet train --eval` and `fusedet experiments` share). A chain of several
// cascades is their AND combination (paper Tab. 7): the first one scans every window, each later
// one must also accept a window it passed, then the surviving windows are grouped into detections.

#include <cstddef>
#include <vector>

#include "fusedet/boost/detection_setup.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/evaluation.h"
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

// Runs the chain on every item and matches against its labels.
EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const MatchConfig& match, const DetectionSetup& setup);
// The same on the items with the given indices (outcomes in that order).
EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const std::vector<std::size_t>& indices, const MatchConfig& match,
                          const DetectionSetup& setup);

}  // namespace fusedet::boosting
