#pragma once
// Detection with a model's aspect cascades (cascade.h `aspectCascades`, e.g. a car cascade trained
// for side views at 2.4:1 beside the 1.5:1 one): the one rule that evaluation, the miss analysis
// and the daemon share.
//
// Each cascade scans at its own window aspect and its hits are grouped alone (grouping.h, the same
// GroupParams); then the detections of all cascades are merged: taken cascade by cascade, each by
// descending score (GroupParams::AspectMerge::kFirstCascadeFirst, the default: an aspect cascade
// only adds detections where the model's own found none) or all by descending score (kByScore;
// ties: cascade order, then their order), a detection is dropped when it overlaps an already kept
// detection of ANOTHER cascade with IoU > GroupParams::aspectMergeIou. Detections of one cascade
// never suppress each other here (their grouping already decided). Output: the kept detections,
// cascade 0's first, each cascade's in its grouping order. A model without aspect cascades gives
// exactly groupHits() of its own hits.
#include <span>
#include <string>
#include <vector>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

// The model's cascades in scan order: the model itself, then its aspect cascades.
std::vector<const Cascade*> cascadesOf(const Cascade& model);

struct MergedDetections {
  std::vector<Detection> detections;
  // kept[k][d]: index in `detections` of cascade k's detection d, or of the detection of another
  // cascade that suppressed it.
  std::vector<std::vector<int>> kept;
};

// The merge above on already grouped detections (perCascade[k] = cascade k's).
MergedDetections mergeCascadeDetections(const std::vector<std::vector<Detection>>& perCascade, double mergeIou,
                                        GroupParams::AspectMerge order);

// Groups hits[k] (cascade k of cascadesOf(model)) and merges them. `fates` (optional) gets per
// cascade one HitFate per hit (grouping.h), its `detection` an index into the merged output.
// Throws std::invalid_argument when hits has not one entry per cascade.
std::vector<Detection> groupModelHits(const Cascade& model, const std::vector<std::vector<RawHit>>& hits,
                                      const GroupParams& group, const LayerStack& stack,
                                      std::vector<std::vector<HitFate>>* fates = nullptr);

// Hits of the detector's model and of each of its aspect cascades (Detector::scan each, same
// ScanParams; each at its own window aspect). stats (optional) adds up every scan's work.
std::vector<std::vector<RawHit>> scanModel(const Detector& detector, const LayerStack& stack, const ScanParams& scan,
                                           ScanStats* stats = nullptr);

}  // namespace fusedet::boosting
