// SPDX-License-Identifier: Apache-2.0
#pragma once
// Gentle AdaBoost for one cascade stage (paper §2, Friedman/Hastie/Tibshirani's Gentle variant):
// each round fits the weighted least-squares stump f_m (stump.h), F += f_m,
// w_i *= exp(-y_i f_m(x_i)), weights renormalised. After every round the stage threshold is the
// largest value that keeps the hit rate on the positives >= minHit; the stage is complete when
// its false-alarm rate on the negatives is <= maxFalseAlarm (or after maxWeak rounds).

#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "fusedet/boost/feature_matrix.h"
#include "fusedet/boost/stump.h"

namespace fusedet::boosting {

struct StageConfig {
  double minHit = 0.995;
  double maxFalseAlarm = 0.5;
  int maxWeak = 100;  // rounds per stage at most
  int threads = 0;
  std::size_t refineTop = 4;
};

struct RoundInfo {
  int round = 0;  // 1-based
  double hitRate = 0, falseAlarm = 0;
  double threshold = 0;
  FittedStump stump;  // feature = row of the matrix
};

struct StageResult {
  std::vector<FittedStump> stumps;  // feature = row of the matrix
  double threshold = 0;             // stage passes when sum of stump outputs >= threshold
  double hitRate = 0, falseAlarm = 0;  // on the training samples, at `threshold`
  bool reachedFalseAlarm = false;   // false: stopped at maxWeak
};

// One round's weak learner for boostStage(): the best stump for the sample weights (float, sample
// order) and, in `chosenValues`, the raw values of its feature on every sample.
using StumpFinder = std::function<FittedStump(std::span<const float> weights, std::span<float> chosenValues)>;

// The Gentle AdaBoost loop over `samples` samples ([0, positives) are positives) with any stump
// finder: trainStage() searches one in-process matrix, sharded_stage.h one sharded over ranks.
StageResult boostStage(std::size_t samples, std::size_t positives, const StumpFinder& find,
                       const StageConfig& config,
                       const std::function<void(const RoundInfo&)>& onRound = {});

// Samples [0, positives) of `m` are positives. rawValues gives the raw values of a matrix row
// (exact refinement and the update use them). onRound (optional) sees every round.
StageResult trainStage(const FeatureMatrix& m, std::size_t positives,
                       const FeatureValuesFn& rawValues, const StageConfig& config,
                       const std::function<void(const RoundInfo&)>& onRound = {});

// Stage threshold for scores of the positives: the largest t with
// |{s >= t}| >= ceil(minHit * n), nudged down by a relative 1e-9 so the detector's sums, added
// in the same order, compare the same way. Exposed for tests.
double stageThreshold(std::vector<double> positiveScores, double minHit);

}  // namespace fusedet::boosting
