#pragma once
// Evaluating the feature pool on the training samples of a stage, fast and exactly as
// featureValue() (feature.h) does. A feature's pixel layout inside a window depends only on the
// window's size on each layer, and the bootstrapped negatives come from a few scan scales, so
// samples are visited grouped by size and each group lays out the features once; each value is
// then three or four table look-ups (and, on contrast-normalised layers, one division by the
// window's standard deviation, computed once per sample). A test checks equality with
// featureValue() bit for bit.

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
  // Values of one feature on every sample (a FeatureValuesFn, stump.h).
  void feature(std::size_t f, std::span<float> out) const;

 private:
  const TrainingStacks& stacks_;
  std::span<const Feature> pool_;
  std::span<const Sample> samples_;
  std::vector<std::size_t> order_;      // samples sorted by their per-layer window sizes
  std::vector<std::size_t> runStart_;   // start of each group of equal sizes in order_, + end
  std::vector<LayerWindow> windows_;    // per sample x layer
  std::vector<double> contrast_;        // per sample x layer: windowContrast() of normalised layers
  std::size_t layers_ = 0;
};

}  // namespace fusedet::boosting
