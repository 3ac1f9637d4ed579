#pragma once
// What one detection runs with, after the model: the scan, the grouping and what follows it (the
// laser extent, the learned box refinement, the group verifier). The per-class settings
// (class_detection.h) and the evaluation loop (chain_evaluation.h) both take it; it lives with
// detection so that detection needs no evaluation code.

#include "fusedet/boost/box_regression.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/group_verifier.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/laser_extent.h"

namespace fusedet::boosting {

struct DetectionSetup {
  ScanParams scan;
  GroupParams group;
  LaserExtentParams laserExtent;  // box refinement after grouping (off by default)
  BoxRegression boxRegression{};  // learned refinement after the laser extent (none by default)
  GroupVerifier verifier{};       // learned group verifier after the boxes (none by default)
};

}  // namespace fusedet::boosting
