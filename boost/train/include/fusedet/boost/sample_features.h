// SPDX-License-Identifier: Apache-2.0
#pragma once
// Evaluating the feature pool on the training samples of a stage, fast and exactly as
// featureValue() (feature.h) does. A feature's pixel layout inside a window depends only on the
// window's size on each layer, and the bootstrapped negatives come from a few scan scales, so
// samples are visited grouped by size and each group lays out the features once; each value is
// then three or four table look-ups. A test checks equality with featureValue() bit for bit.

#include <cstddef>
#include <span>
#include <vector>

#include "fusedet/boost/feature.h"
#include "fusedet/boost/training_set.h"

namespace fusedet::boosting {

class SampleFeatures {
 public:
  // Keeps references: stacks, pool and samples must outlive this object.
  SampleFeatures(const TrainingStacks& stacks, std::span<const Feature> pool,
                 std::span<const Sample> samples);

  // Values of features [first, first + count) on every sample, feature-major into out
  // (count x samples): a FeatureBlockFn (feature_matrix.h).
  void block(std::size_t first, std::size_t count, std::span<float> out) const;
  // The same into rows of `rowStride` values starting at column `column0` (out[k * rowStride +
  // column0 + i]), so that a caller can put other samples' values beside these.
  void block(std::size_t first, std::size_t count, std::span<float> out, std::size_t rowStride,
             std::size_t column0) const;
  // Values of one feature on every sample (a FeatureValuesFn, stump.h).
  void feature(std::size_t f, std::span<float> out) const;

 private:
  const TrainingStacks& stacks_;
  std::span<const Feature> pool_;
  std::span<const Sample> samples_;
  std::vector<std::size_t> order_;      // samples sorted by their per-layer window sizes
  std::vector<std::size_t> runStart_;   // start of each group of equal sizes in order_, + end
  std::vector<LayerWindow> windows_;    // per sample x layer
  std::size_t layers_ = 0;
};

// The pool on every positive of a training, evaluated once: the positives are the same windows in
// every stage (a stage takes those the cascade still accepts), so only the negatives are new.
// Feature-major, pool x positives floats (bytes()): the trainer keeps it when it is small enough.
class PositiveFeatures {
 public:
  PositiveFeatures(const TrainingStacks& stacks, std::span<const Feature> pool, int threads);
  static std::size_t bytes(std::size_t poolSize, std::size_t positives) { return poolSize * positives * sizeof(float); }
  // Values of feature f on every positive (stacks.positives() order).
  const float* feature(std::size_t f) const { return values_.data() + f * positives_; }

 private:
  std::vector<float> values_;
  std::size_t positives_ = 0;
};

// A stage's samples: the accepted positives (indices into stacks.positives(), values from the
// cache) followed by the stage's negatives (evaluated by SampleFeatures). Values equal
// SampleFeatures' on the same samples bit for bit. Keeps references.
class StageFeatures {
 public:
  StageFeatures(const PositiveFeatures& positives, std::span<const std::size_t> accepted,
                const TrainingStacks& stacks, std::span<const Feature> pool, std::span<const Sample> negatives);
  std::size_t samples() const { return accepted_.size() + negatives_.size(); }
  void block(std::size_t first, std::size_t count, std::span<float> out) const;  // a FeatureBlockFn
  void feature(std::size_t f, std::span<float> out) const;                       // a FeatureValuesFn

 private:
  const PositiveFeatures& positives_;
  std::span<const std::size_t> accepted_;
  std::span<const Sample> negatives_;
  SampleFeatures negativeValues_;
};

}  // namespace fusedet::boosting
