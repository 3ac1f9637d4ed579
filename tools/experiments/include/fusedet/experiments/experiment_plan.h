// SPDX-License-Identifier: Apache-2.0
#pragma once
// What one `fusedet experiments` run does, as a named preset: the training of every fold's
// cascade, the detection on the test frames, the fold design, the configurations and for which
// classes they run, and the learning curve. One preset reproduces docs/results in one command:
//
//  - "bundled" (the default): the training of the bundled models (models/README.md: grid 8, at
//    most 14 stages of at most 100 stumps, target 1e-5, negatives max(500, 2 x positives),
//    training scan 1.2 / 3); leave-one-drive-out for the headline (`all`, every class) and for the
//    paper's configurations (no_corners, laser, camera, and) and `channels`, which run for car
//    only (person and bike have too few positives for a comparison to say anything:
//    docs/results); learning curves of `all` (1, 2, 4, 8 and all training drives) on 3
//    drive-disjoint folds, because 22 leave-one-drive-out folds per point are about 7x as many trainings;
//    the same curve over 8, 16, 32, 64, 128 and all training positives per fold; every point
//    scored on its own training frames too.
//  - "quick": the same plan scaled down to a smoke test of a minute or two (grid 6, at most 4
//    stages of 5 stumps, coarse scans, 3 drive-disjoint folds, 200 resamples, configurations
//    without `channels`, two-point learning curves over drives and positives); its numbers mean little.
//
// Options of `fusedet experiments` override single fields; the plan is the default.

#include <cstddef>
#include <string>
#include <vector>

namespace fusedet::boosting {

struct ExperimentPlan {
  std::string name;
  // Training of every fold's cascade (TrainingConfig fields).
  int grid = 8;
  int maxStages = 14;
  int maxWeak = 100;
  double targetFalseAlarm = 1e-5;
  std::size_t negatives = 0;  // 0 = the trainer's rule, max(500, 2 x positives)
  double trainScaleFactor = 1.2, trainStep = 3;
  // Detection on the test frames; with classDetection a class that has its own settings
  // (class_detection.h: car) is detected with those instead.
  double scaleFactor = 1.2, step = 3;
  bool classDetection = true;
  // Folds of the headline and the configurations: 0 = leave-one-drive-out, k = k drive-disjoint
  // folds (data_split.h crossGroupFolds).
  int folds = 0;
  std::size_t resamples = 1000;  // bootstrap resamples of the frames
  // Configurations: `all` runs for every class (the headline); the others only for
  // `configClasses` (empty = every class).
  std::vector<std::string> configs;
  std::vector<std::string> configClasses;
  // Learning curve of `all`: training drives per fold (0 = all of them), on `learningFolds` folds
  // (same meaning as `folds`; the `all` point reuses the headline when both fold designs agree).
  std::vector<std::size_t> learningDrives;
  // The same curve over training positives of the class per fold (0 = all): a seeded nested
  // subset of each fold's training frames grown until it holds that many (data_split.h
  // learningPositivesFold), on the same folds.
  std::vector<std::size_t> learningPositives;
  int learningFolds = 3;
  // Every learning-curve point is also scored on its folds' own training frames (bias against
  // variance: cross_validation.h ChainSpec::scoreTrainingItems).
  bool trainingScore = true;
  double peerUpscale = 2;  // HOG people detector: images enlarged by this factor
};

// The preset of that name; throws std::invalid_argument naming the known ones.
ExperimentPlan experimentPlan(const std::string& name);
// "bundled", "quick": every name experimentPlan() knows, the default first.
const std::vector<std::string>& experimentPlanNames();

// Whether `config` runs for class `cls` under the plan (`all` always does).
bool runsFor(const ExperimentPlan& plan, const std::string& config, const std::string& cls);

}  // namespace fusedet::boosting
