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

// Which labels of a class become TRAINING positives. Evaluation never changes (matchConfigFor():
// KITTI moderate); this rule widens only what the trainer is shown, so that more distinct objects
// train the cascade. Levels (the devkit's difficulty limits):
//   moderate (default) = the evaluation positives: height >= 25 px, occlusion <= 1,
//            truncation <= 0.3 (tracking labels: level 0);
//   hard     = height >= 25 px, occlusion <= 2, truncation <= 0.5 (tracking labels: level <= 1).
// minHeight > 0 replaces the level's 25 px (e.g. 18: also the smaller cars); vans (car only):
// KITTI Van labels within the same limits train as cars (in evaluation Van stays the ignored
// neighbouring class). A label of the class (or a van) outside the rule stays an ignored label in
// training: its windows are never negatives.
struct TrainingPositives {
  enum class Level { kModerate, kHard };
  Level level = Level::kModerate;
  double minHeight = 0;  // pixels; 0 = the level's (25)
  bool vans = false;
  bool isDefault() const { return level == Level::kModerate && minHeight == 0 && !vans; }
};
// "moderate" | "hard", optionally followed by ",vans" and/or ",min-height=N" (N > 0 pixels), e.g.
// "hard,vans,min-height=18". Throws std::invalid_argument naming what is wrong.
TrainingPositives parseTrainingPositives(const std::string& text);
// The canonical text parseTrainingPositives() reads back ("moderate" for the default).
std::string toString(const TrainingPositives& rule);

// The MatchConfig whose positives are the training positives of `rule`: `evaluation` (from
// matchConfigFor()) with the level's limits, the minimum height and vans as aliases of car (no
// longer neighbours). truncationLevels: the labels' truncation is a KITTI tracking level (0, 1, 2),
// not a fraction; the hard level then keeps levels 0 and 1 (limit 1 instead of 0.5). The moderate
// level's 0.3 keeps level 0 either way, as evaluation does. Returns `evaluation` unchanged for the
// default rule. Throws std::invalid_argument for vans with a class other than car.
MatchConfig trainingMatchConfig(const MatchConfig& evaluation, const TrainingPositives& rule,
                                bool truncationLevels = false);

// Per class: positives (moderate), ignored labels and frames holding a positive.
struct InstanceCount {
  std::size_t positives = 0, ignoredLabels = 0, frames = 0;
};
InstanceCount countInstances(const std::vector<Labels>& frames, const MatchConfig& config);

}  // namespace fusedet::boosting
