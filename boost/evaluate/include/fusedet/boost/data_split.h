// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which frames train and which test: the one home of the split rules that `fusedet train`,
// `fusedet eval`, `fusedet demo` and `fusedet experiments` use.
//  - splitByFrame: within each group (drive), in frame order, the first share trains. Frames of
//    one drive share the same physical objects, so this measures little about a new street.
//  - crossGroupFolds: leave-one-group-out (every group, i.e. raw drive, is the test set once,
//    trained on all others), or groups dealt into k folds for a cheaper run.
//  - learningCurveFold: a seeded subset of a fold's training groups (F against the number of
//    training drives).
//  - learningPositivesFold: a seeded subset of a fold's training items (frames) holding at least N
//    positives of a class (F against the number of training positives: drives are very unequal).

#include <cstddef>
#include <cstdint>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "fusedet/core/dataset.h"

namespace fusedet::boosting {

struct Split {
  std::vector<DatasetEntry> train, test;
};

// Per group, in manifest (= frame) order: the first round(n * trainFraction) frames train, the
// rest test; groups in `trainOnly` train entirely. Throws std::invalid_argument for a fraction
// outside [0, 1].
Split splitByFrame(const std::vector<DatasetEntry>& entries, double trainFraction = 2.0 / 3.0,
                   const std::set<std::string>& trainOnly = {});

// The first test frame of a group of n frames under splitByFrame (n when none is held back).
std::size_t firstTestFrame(std::size_t frames, double trainFraction = 2.0 / 3.0);

// One fold: the held-out groups and item indices (into the list the folds were made from).
struct Fold {
  std::vector<std::string> testGroups;
  std::vector<std::size_t> train, test;  // ascending
};

// groupOfItem[i] = the group (raw drive) of item i. folds = 0: one fold per group
// (leave-one-group-out); folds = k < groups: groups sorted by name and dealt round-robin into k
// folds. Folds come in order of their first group's name. Throws for fewer than 2 groups.
std::vector<Fold> crossGroupFolds(const std::vector<std::string>& groupOfItem, std::size_t folds = 0);

// A fold restricted to `groups` of its training groups, chosen by a seeded shuffle (the same
// seed, fold and count give the same choice; a larger count keeps the smaller one's groups).
// groups >= the fold's training groups returns the fold unchanged.
Fold learningCurveFold(const Fold& fold, const std::vector<std::string>& groupOfItem, std::size_t groups,
                       std::uint64_t seed);

// A fold restricted to a seeded random subset of its training items: one shuffle of them per
// (seed, fold), taken from the front until the items hold at least `minPositives` positives
// (positivesOfItem[i] = positives of the class in item i). Prefixes of one shuffle, so a larger
// count keeps the smaller one's items (nested). minPositives = 0, or more than the fold's training
// items hold, returns the fold unchanged. Training items stay in ascending order.
Fold learningPositivesFold(const Fold& fold, const std::vector<std::size_t>& positivesOfItem,
                           std::size_t minPositives, std::uint64_t seed);

// Number of distinct groups among the fold's training items.
std::size_t trainingGroupCount(const Fold& fold, const std::vector<std::string>& groupOfItem);

}  // namespace fusedet::boosting
