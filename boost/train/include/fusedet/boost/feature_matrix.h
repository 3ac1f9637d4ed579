// SPDX-License-Identifier: Apache-2.0
#pragma once
// FeatureMatrix: the feature values of one training stage, quantised once into 8-bit bins per
// feature and stored feature-major (row f = feature f over all samples), so that every boosting
// round only builds small per-feature histograms (the LightGBM/XGBoost "hist" idea, kept apart
// from the split search in stump.h). Raw values are not kept: the chosen split is refined
// exactly from recomputed raw values (stump.h), so the matrix stays at one byte per entry.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace fusedet::boosting {

class FeatureMatrix {
 public:
  static constexpr int kMaxBins = 256;
  static constexpr std::size_t kEdgeSample = 1024;  // values binEdges() looks at

  FeatureMatrix() = default;
  FeatureMatrix(std::size_t features, std::size_t samples);

  // Quantises the raw values of feature f (one per sample) into row f: samples ranked by value
  // (radix sort), equal values share a bin, bins are equal-count quantiles (or one bin per value
  // when there are at most kMaxBins distinct values). Thread-safe for distinct f.
  void setFeature(std::size_t f, std::span<const float> values);

  // Bins the raw values of feature f with given edges (binEdges(); at most kMaxBins - 1): bin =
  // number of edges <= value, NaN in the last bin. Sharded training bins every rank's samples with
  // edges from one global subsample (sharded_stage.h). Thread-safe for distinct f.
  void setFeature(std::size_t f, std::span<const float> values, std::span<const float> edges);

  std::size_t features() const { return features_; }
  std::size_t samples() const { return samples_; }
  const std::uint8_t* row(std::size_t f) const { return bins_.data() + f * samples_; }
  std::size_t bytes() const { return bins_.size(); }

 private:
  std::vector<std::uint8_t> bins_;  // features_ x samples_
  std::vector<std::uint8_t> quantileBin_;  // per rank p: p * kMaxBins / samples_
  std::size_t features_ = 0, samples_ = 0;
};

// Raw values of features [first, first + count) for every sample, written feature-major into
// out (count x samples). Called concurrently for disjoint blocks.
using FeatureBlockFn = std::function<void(std::size_t first, std::size_t count, std::span<float> out)>;

// Builds the matrix block by block (threads over blocks of `block` features; `threads` = 0 means
// all cores). Peak extra memory: threads x block x samples floats.
FeatureMatrix buildFeatureMatrix(std::size_t features, std::size_t samples,
                                 const FeatureBlockFn& values, int threads = 0,
                                 std::size_t block = 512);

// Quantile bin edges of a strided subsample of one feature's values (sorted, strictly increasing,
// at most kMaxBins - 1; v falls into bin = number of edges <= v): for callers that bin values
// the matrix has not seen.
std::vector<float> binEdges(std::span<const float> values);

}  // namespace fusedet::boosting
