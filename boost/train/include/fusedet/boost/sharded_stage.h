// SPDX-License-Identifier: Apache-2.0
#pragma once
// One boosting stage of a sharded training job (LightGBM's data-parallel scheme, made exact):
//   - each rank evaluates the pool on the stage's samples that lie on its own stacks and bins
//     them with edges from one global subsample (binEdges() of every (n / 1024)-th sample, the
//     subsample's values gathered from their owners), so a sample gets the same bin on any rank;
//   - per round each rank builds histograms of its samples in fixed point (weight x 2^30 as
//     int32: integer sums are exact, so the reduced histograms are the same for any rank count),
//     a reduce-scatter sums them and gives each rank a slice of the features to scan, and the
//     best binned splits are all-gathered and merged (gain, then feature, then bin);
//   - the raw values of those few candidate features are all-gathered into sample order and every
//     rank refines them exactly (fitStumpExact) and updates the weights identically.
// Every rank therefore picks the same stump and ends with the same stage, for 1, 2 or N ranks.
// (A one-rank job with this path can differ from the in-process trainer, whose bins are exact
// quantiles of all values and whose histograms are float.)

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

#include "fusedet/boost/collective.h"
#include "fusedet/boost/feature.h"
#include "fusedet/boost/feature_matrix.h"
#include "fusedet/boost/sample_features.h"
#include "fusedet/boost/stump.h"
#include "fusedet/boost/training_set.h"

namespace fusedet::boosting {

class ShardedStage {
 public:
  // `samples`: the stage's samples in global order, [0, positives) positives, the same list on
  // every rank. Keeps references to stacks, pool and job. Builds the local matrix (collective).
  ShardedStage(const TrainingStacks& stacks, std::span<const Feature> pool, std::vector<Sample> samples,
               std::size_t positives, Collective& job, int threads);

  // A StumpFinder (gentle_boost.h) for boostStage(): collective, call on every rank.
  FittedStump findStump(std::span<const float> weights, std::span<float> chosenValues, std::size_t refineTop);

  std::size_t localSamples() const { return local_.size(); }
  std::size_t matrixBytes() const { return matrix_.bytes(); }

 private:
  void buildMatrix();
  // Values of features on every sample in global order, from each rank's local values.
  std::vector<std::vector<float>> gatherValues(const std::vector<std::size_t>& features);

  const TrainingStacks& stacks_;
  std::span<const Feature> pool_;
  Collective& job_;
  int threads_;
  std::vector<Sample> samples_;       // global
  std::size_t positives_;             // global
  std::vector<std::size_t> local_;    // global indices of this rank's samples, ascending
  std::vector<Sample> localSamples_;  // samples_[local_[k]]
  std::size_t localPositives_ = 0;
  std::vector<std::size_t> rankOrder_;     // global indices, ranks' local lists concatenated
  std::vector<std::size_t> rankCounts_;    // samples per rank
  SampleFeatures values_;
  FeatureMatrix matrix_;
};

}  // namespace fusedet::boosting
