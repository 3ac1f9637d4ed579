#pragma once
// `fusedet experiments`, data side: the train/test split by frame within each group (drive), the
// class rules (what a label means when a class is trained or evaluated), instance counts.

#include <map>
#include <string>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/core/dataset.h"

namespace fusedet::tools::experiments {

struct Split {
  std::vector<DatasetEntry> train, test;
};

// Per group, in manifest (= frame) order: the first round(n * trainFraction) frames train, the
// rest test. Consecutive frames of a drive are nearly identical, so splitting in time keeps the
// test frames from being near-copies of training frames (as far as one drive allows).
Split splitByFrame(const std::vector<DatasetEntry>& entries, double trainFraction = 2.0 / 3.0);

// What a KITTI "Van" is when evaluating or training "car".
enum class VanPolicy { kNegative, kIgnore, kPositive };
VanPolicy parseVanPolicy(const std::string& text);  // "negative" | "ignore" | "positive"
std::string toString(VanPolicy policy);

// Evaluation rules for one class: KITTI moderate (height >= 25 px, occlusion <= 1), IoU >= 0.5,
// ignore regions (Label::ignore: DontCare, Truck, Tram, Misc, Person_sitting), van per policy.
boosting::MatchConfig matchConfigFor(const std::string& className, VanPolicy van);

// Labels as the trainer should see them for one class: positives are the labels that are
// positives in evaluation; labels of the class below moderate difficulty become ignore regions
// (neither positives nor negative windows); ignore regions stay; everything else is removed,
// so vans (policy negative), other classes and the background are negative material.
Labels trainingLabels(const Labels& labels, const boosting::MatchConfig& config);

// Per class: positives (moderate), ignored labels (below moderate) and frames holding a positive.
struct InstanceCount {
  std::size_t positives = 0, ignoredLabels = 0, frames = 0;
};
InstanceCount countInstances(const std::vector<Labels>& frames, const boosting::MatchConfig& config);

}  // namespace fusedet::tools::experiments
