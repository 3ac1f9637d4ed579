// SPDX-License-Identifier: Apache-2.0
#pragma once
// Cross-drive validation (data_split.h folds): for each fold a cascade is trained on the training
// groups' items (labels as trainingLabels() gives them for the class) and run on the held-out
// items; every item is tested exactly once, so the per-item outcomes pool over the folds into one
// test set (F, AP, bootstrap intervals over frames: bootstrap.h).
//
// Training is the expensive part, so fold models are cached: a model file named by a hash of the
// training configuration and the training items' ids is reused when present. The key does not
// see code changes: use a fresh cache directory after changing the trainer.

#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/miss_analysis.h"
#include "fusedet/core/dataset.h"
#include "fusedet/core/label.h"

namespace fusedet::boosting {

// Text of every setting of a training configuration that changes the model (one per line).
std::string describeTrainingConfig(const TrainingConfig& config);
// 16 hex digits: FNV-1a 64 of the description, the training item ids in order and, when not
// empty, `trainingLabels`: the labelsKey() of labels trained on that are not the data set's own
// (fusedet experiments --train-labels), so a model trained on other labels is never reused.
std::string trainingKey(const TrainingConfig& config, const std::vector<std::string>& itemIds,
                        const std::string& trainingLabels = "");
// 16 hex digits: FNV-1a 64 of every item's labels (class, source class, box, truncation,
// occlusion, ignore, origin), items in order.
std::string labelsKey(const std::vector<Labels>& labels);

// Where trainOrLoad()'s model came from: its cache key, whether it was loaded from the cache, and
// its training time - measured now, or as its file records it (0 if none), so a run from the
// cache can still say what it would cost without one.
struct FoldModel {
  std::string key;
  bool cached = false;
  double trainSeconds = 0;
};

// Trains on items[train] (or loads `cacheDir/<key>.json` when it exists; empty cacheDir = no
// cache) and writes the model there; `trainingLabels` as trainingKey() takes it. `fromCache` tells which; `source` gets the details. Throws
// what trainCascade throws (e.g. too few positives).
Cascade trainOrLoad(const TrainingConfig& config, const std::vector<DatasetItem>& items,
                    const std::vector<std::size_t>& train, const std::filesystem::path& cacheDir,
                    const std::string& trainingLabels, ProgressSink& progress, TrainingReport* report = nullptr, bool* fromCache = nullptr,
                    FoldModel* source = nullptr);

// Outcome of one configuration over all folds.
struct CrossValidationResult {
  // Per item. A fold whose cascade cannot be trained (e.g. too few positives) detects nothing: its
  // positives count as misses, so a failure is never left out of the pooled numbers.
  std::vector<FrameOutcome> frames;
  std::vector<std::string> failures;                // "fold <groups>: <why>" of untrained folds
  std::vector<CascadeSummary> summaries;            // per trained fold
  double trainSeconds = 0, msPerStack = 0;          // summed training; mean detection time
  std::size_t cachedFolds = 0;
  double cachedTrainSeconds = 0;  // training time the cached folds' model files record, summed
  // Every fold model by key, as first used: configurations sharing a model (the AND and its
  // parts) count it once when a run sums these, and a model trained earlier in the same run is
  // not counted again as cached.
  std::map<std::string, FoldModel> models;
  // With ChainSpec::scoreTrainingItems: one outcome per (fold, training item), folds in order and
  // each fold's training items in ascending order; an item trains in several folds, so it appears
  // once per fold. An untrained fold detects nothing on its training items either.
  std::vector<FrameOutcome> trainingFrames;
  // Per item, what became of each positive (ChainSpec::analyseMisses, one-cascade chains only).
  std::vector<std::vector<PositiveOutcome>> positives;
  // With both analyseMisses and scoreTrainingItems: the same per (fold, training item), in the
  // order of trainingFrames - where a cascade loses the objects it was trained on.
  std::vector<std::vector<PositiveOutcome>> trainingPositives;
};

// A configuration: one or more training configs whose cascades are chained (AND) at detection.
struct ChainSpec {
  std::vector<TrainingConfig> parts;
  // > 0: each part is evaluated cut to its first `keepStages` stages (firstStages(): the cascade
  // training with that stage limit gives), so one trained (cached) model serves every stage count.
  std::size_t keepStages = 0;
  // Also run each fold's chain on its OWN training items (same detection, same KITTI rules, the
  // items' labels as the test items hold them): the training score beside the held-out one that
  // tells a data limit (high on training, low held out) from a method limit (low on both).
  bool scoreTrainingItems = false;
  // Also explain every missed positive (miss_analysis.h) into CrossValidationResult::positives
  // (and, with scoreTrainingItems, into trainingPositives); needs a chain of one cascade.
  bool analyseMisses = false;
  // Empty: the cascades train on the data set's own labels. Else they train on labels from
  // another data set of the same items (trainingItems' labels; fusedet experiments --train-labels)
  // and this is their labelsKey(): it goes into every fold model's cache key.
  std::string trainingLabels{};
};

// Runs `spec` over the folds: per fold trains (or loads) each part, evaluates the chain on the
// fold's test items. `progress` gets a line per fold. A learning-curve point is this run on the
// point's folds (data_split.h learningCurveFold / learningPositivesFold).
CrossValidationResult crossValidate(const ChainSpec& spec, const std::vector<DatasetItem>& trainingItems,
                                    const std::vector<DatasetItem>& testItems, const std::vector<Fold>& folds,
                                    const MatchConfig& match, const DetectionSetup& setup,
                                    const std::filesystem::path& cacheDir, ProgressSink& progress,
                                    const std::function<void(const std::string&)>& log = {});

}  // namespace fusedet::boosting
