// SPDX-License-Identifier: Apache-2.0
#pragma once
// Training a cascade for one class (paper §2-§4, design.md §5): the library entry point that
// `fusedet train` and `fusedet experiments` call.
//
//   Cascade trainCascade(const TrainingConfig&, const std::vector<DatasetItem>& train,
//                        ProgressSink&, TrainingReport* = nullptr);
//
// Per stage: positives still accepted by the cascade so far; negatives bootstrapped from the
// label-free windows the cascade still accepts (training_set.h); the feature pool evaluated on
// all samples once and quantised (feature_matrix.h); Gentle AdaBoost rounds (gentle_boost.h)
// until the stage's false-alarm rate <= maxFalseAlarm at hit rate >= minHit. Stages are added
// until the cascade accepts no more than targetFalseAlarm of the label-free windows, the stage
// limit is reached, or too few negatives (or positives) remain; TrainingReport::stopReason says
// which, with the numbers. Same config (seed) + same data => identical cascade, for any thread
// count.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/collective.h"
#include "fusedet/boost/feature_pool.h"
#include "fusedet/boost/gentle_boost.h"
#include "fusedet/boost/training_set.h"
#include "fusedet/core/dataset.h"

namespace fusedet::boosting {

struct TrainingConfig {
  std::string className = "car";
  PoolConfig pool;        // layers, feature types, grid
  SampleConfig samples;   // className is taken from above
  StageConfig stage;      // min_hit, max_fa, rounds per stage
  double targetFalseAlarm = 1e-5;     // of the label-free windows scanned
  int maxStages = 20;
  std::size_t negativesPerStage = 0;  // 0 = max(500, 2 x positives)
  std::size_t minNegatives = 50;      // fewer still-accepted negatives end training
  std::size_t minPositives = 10;      // fewer still-accepted positives end training
  std::uint64_t seed = 1;
  int threads = 0;                    // 0 = all cores
  // Negative mining: true = incremental (negative_miner.h: each stage evaluates only its new
  // stage on the windows still accepted), false = every window of every stack rescanned with the
  // whole cascade (TrainingStacks::harvestNegatives()). Same negatives, same model either way;
  // false is the reference path the tests compare with.
  bool incrementalMining = true;
  // The pool's values on every positive are evaluated once per training and kept (pool x
  // positives floats, sample_features.h) when they take at most this many bytes; above that
  // they are evaluated again each stage. Same values either way.
  std::size_t positiveCacheBytes = std::size_t(1) << 30;

  // Throws std::invalid_argument naming the bad setting.
  void validate() const;
};

struct StageReport {
  int stage = 0;  // 1-based
  int weak = 0;   // stumps
  double hitRate = 0, falseAlarm = 0;  // on this stage's training samples
  bool reachedFalseAlarm = false;      // false: stopped at the round limit
  std::size_t positives = 0, negatives = 0;
  std::size_t windowsScanned = 0;      // bootstrapping scan before this stage
  std::size_t negativeCandidates = 0;  // label-free windows the cascade accepted then
  double cascadeFalseAlarm = 1;        // candidates / candidates before stage 1
  double seconds = 0;
  // Where the time went: bootstrapping scan, pool evaluation + binning, boosting rounds.
  double harvestSeconds = 0, matrixSeconds = 0, boostSeconds = 0;
  std::size_t matrixBytes = 0;  // the stage's 8-bit feature matrix (pool x samples)
};

struct TrainingReport {
  std::size_t poolSize = 0;
  std::size_t positives = 0;  // incl. mirrored copies
  int windowWidth = 0, windowHeight = 0;
  int minHeight = 0;  // the smallest training positive's height, floored
  std::optional<double> referenceHue;
  std::vector<StageReport> stages;
  double finalFalseAlarm = 1;  // of the label-free windows, after the last stage
  std::string stopReason;      // e.g. "reached the target false-alarm rate: 8.1e-06 <= 1e-05"
  double seconds = 0;
};

enum class ProgressKind { kStart, kStageStart, kNegatives, kRound, kStageDone, kFinished };

struct ProgressEvent {
  ProgressKind kind = ProgressKind::kStart;
  int stage = 0, maxStages = 0;  // 1-based stage
  int round = 0, maxRounds = 0;
  double hitRate = 0, falseAlarm = 0;        // current stage, on its samples
  std::size_t positives = 0, negatives = 0;  // samples of the current stage
  std::size_t windowsScanned = 0;
  double cascadeFalseAlarm = 1;
  double elapsedSeconds = 0;
  std::string message;  // human-readable line for kStart, kStageDone, kFinished
};

class ProgressSink {
 public:
  virtual ~ProgressSink() = default;
  virtual void onProgress(const ProgressEvent& event) = 0;
};

class NullProgress : public ProgressSink {
 public:
  void onProgress(const ProgressEvent&) override {}
};

// Trains; throws std::invalid_argument for a bad config and std::runtime_error when the data has
// no positives of the class or lacks a selected layer (the message names the item).
//
// With `job` (collective.h) training is sharded over its ranks, each calling this with the same
// config and item list: item i's pixels are needed only on rank i % job->size() (the others may
// hold just labels and reference size, readDatasetItemLabels()); see sharded_samples.h and
// sharded_stage.h. Every rank returns the same cascade, identical for any number of ranks (but
// not necessarily equal to the in-process trainer's: sharded_stage.h says why). Progress events
// are sent on every rank (callers show rank 0's); stage times and matrix sizes are this rank's.
Cascade trainCascade(const TrainingConfig& config, const std::vector<DatasetItem>& train,
                     ProgressSink& progress, TrainingReport* report = nullptr, Collective* job = nullptr);

// Reference hue of config.className's positives in `items` (reference_hue.h), from their hue
// layer: their distinctive hue. Throws std::runtime_error when no positive has hue values.
double classReferenceHue(const std::vector<DatasetItem>& items, const SampleConfig& samples);

}  // namespace fusedet::boosting
