#pragma once
// Running cascades over data set items and scoring them: what `fusedet eval` and
// `fusedet experiments` share. A chain of several cascades is their AND combination (paper
// Tab. 7): the first one scans every window, each later one must also accept a window it passed,
// then the surviving windows are grouped into detections.

#include <cstddef>
#include <vector>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/core/dataset.h"

namespace fusedet::tools::experiments {

struct DetectionSetup {
  boosting::ScanParams scan;
  boosting::GroupParams group;
};

struct EvalOutcome {
  boosting::Counts counts;
  double msPerStack = 0;  // mean wall time per stack: integral images + scan + AND + grouping
  std::vector<std::vector<Detection>> detections;  // per item
  std::vector<boosting::StackMatch> matches;       // per item
  std::size_t windows = 0, stumps = 0;             // work done by the first cascade's scan
};

// Detections of a chain of detectors (AND) on one stack; adds the scan's work to `stats`.
std::vector<Detection> detectChain(const std::vector<const boosting::Detector*>& chain,
                                   const LayerStack& stack, const DetectionSetup& setup,
                                   boosting::ScanStats* stats = nullptr);

// Runs the chain on every item and matches against its labels.
EvalOutcome evaluateChain(const std::vector<const boosting::Detector*>& chain,
                          const std::vector<DatasetItem>& items, const boosting::MatchConfig& match,
                          const DetectionSetup& setup);

}  // namespace fusedet::tools::experiments
