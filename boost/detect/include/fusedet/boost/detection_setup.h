// SPDX-License-Identifier: Apache-2.0
#pragma once
// What one detection runs with, after the model: the scan, the grouping and what follows it (the
// laser extent). The per-class settings (class_detection.h) and the evaluation loop
// (chain_evaluation.h) both take it; it lives with detection so that detection needs no evaluation
// code.

#include "fusedet/boost/detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/laser_extent.h"

namespace fusedet::boosting {

struct DetectionSetup {
  ScanParams scan;
  GroupParams group;
  LaserExtentParams laserExtent;  // box refinement after grouping (off by default)
};

}  // namespace fusedet::boosting
