// SPDX-License-Identifier: Apache-2.0
#pragma once
// What a learning-curve point was trained on: the training items of a fold counted for one class
// - items, positives (KITTI moderate, evaluation.h labelRole), distinct groups (raw drives) and
// distinct physical objects among the positives. The curve's x axis is the number of positives
// (data_split.h learningPositivesFold), because drives are very unequal; the objects tell how
// much of that is the same car or rider seen again in the next frame.

#include <cstddef>
#include <string>
#include <vector>

#include "fusedet/boost/data_split.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/core/label.h"

namespace fusedet::boosting {

// Positives of the class in each item's labels (labelRole == kPositive under `match`).
std::vector<std::size_t> positivesPerItem(const std::vector<Labels>& labels, const MatchConfig& match);

struct TrainingSetCount {
  std::size_t items = 0, positives = 0, groups = 0, objects = 0;
};

// Counts of the fold's training items. objectIdOf[i][j] names the physical object of label j of
// item i (e.g. a KITTI tracking id with its drive); an empty name, or a missing entry, is an
// object of its own (a label of the object benchmark counts once). Throws std::out_of_range for
// an index outside `labels` or `groupOfItem`.
TrainingSetCount countTrainingSet(const Fold& fold, const std::vector<Labels>& labels,
                                  const std::vector<std::string>& groupOfItem,
                                  const std::vector<std::vector<std::string>>& objectIdOf, const MatchConfig& match);

}  // namespace fusedet::boosting
