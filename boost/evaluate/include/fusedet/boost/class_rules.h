// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a label means for one class, in evaluation and in training: the KITTI rules of
// evaluation.h made concrete per project class (the one place that decides them).

#include <string>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/core/label.h"

namespace fusedet::boosting {

// What a KITTI "Van" is for "car": ignore = the devkit's neighbouring class (an ignored label,
// the default), negative = background (a detection on it is a false alarm), positive = alias.
enum class VanPolicy { kIgnore, kNegative, kPositive };
VanPolicy parseVanPolicy(const std::string& text);  // "ignore" | "negative" | "positive"
std::string toString(VanPolicy policy);

// The KITTI object devkit's minimum overlap of a hit in 2D (evaluate_object.cpp): 0.7 for car,
// 0.5 for pedestrian and cyclist (and any other class).
double kittiMinOverlap(const std::string& className);

// KITTI moderate for one class: height >= 25 px, occlusion <= 1, truncation <= 0.3, IoU >=
// kittiMinOverlap(class) (car 0.7, person and bike 0.5), detections < 25 px ignored; neighbour classes Van (car, per policy) and Person_sitting (person);
// DontCare absorbs; Truck, Tram, Misc are false alarms.
// minIou > 0 replaces the devkit's overlap for this class (e.g. 0.5 = PASCAL, the tools' --min-iou).
MatchConfig matchConfigFor(const std::string& className, VanPolicy van = VanPolicy::kIgnore, double minIou = 0);

// Labels as the trainer should see them for one class: positives are the labels that are
// positives in evaluation (aliases renamed to the class); ignored labels (below moderate or of
// the neighbouring class) and ignore regions become ignore regions (neither positives nor
// negative windows); background labels are removed, so they and the background are negative
// material (Truck, Tram, Misc included: they are false alarms in evaluation too).
Labels trainingLabels(const Labels& labels, const MatchConfig& config);

// Per class: positives (moderate), ignored labels and frames holding a positive.
struct InstanceCount {
  std::size_t positives = 0, ignoredLabels = 0, frames = 0;
};
InstanceCount countInstances(const std::vector<Labels>& frames, const MatchConfig& config);

}  // namespace fusedet::boosting
