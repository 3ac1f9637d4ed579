// SPDX-License-Identifier: Apache-2.0
#pragma once
// The weak learner: a regression stump (CART of depth 1) fitted by weighted least squares on
// labels y = +1 (positives) / -1 (negatives). Found in two steps, as LightGBM does:
//   1. per feature a weighted histogram over its 8-bit bins (threads over features) and a scan
//      over the bins for the split with the largest gain (least squared error);
//   2. exact refinement: for the best few candidates the raw values are recomputed and every
//      split between two distinct values is scanned; the best exact split wins.
// Ties go to the smaller feature index (then the smaller threshold): deterministic for any
// thread count.

#include <cstddef>
#include <cstdint>
#include <functional>
#include <limits>
#include <span>
#include <vector>

#include "fusedet/boost/feature_matrix.h"

namespace fusedet::boosting {

// f(x) = value < threshold ? left : right.
struct FittedStump {
  std::size_t feature = 0;
  float threshold = std::numeric_limits<float>::infinity();
  double left = 0, right = 0;
  double error = 0;  // weighted squared error sum_i w_i (y_i - f(x_i))^2 on the training samples

  double operator()(float value) const { return value < threshold ? left : right; }
};

// A binned split: bins <= bin go left. gain = S_L^2/W_L + S_R^2/W_R with S = sum w*y, W = sum w;
// the squared error is sum(w) - gain, so larger gain = better stump.
struct SplitCandidate {
  std::size_t feature = 0;
  int bin = 0;
  double gain = -1;
};

// The order of candidates: larger gain first, then smaller feature, then smaller bin.
bool betterSplit(const SplitCandidate& a, const SplitCandidate& b);
// Inserts c into `top` (kept sorted by betterSplit) and keeps the best k.
void keepBestSplits(std::vector<SplitCandidate>& top, const SplitCandidate& c, std::size_t k);
// The features of `candidates` in the order they are refined exactly: ascending, so the exact
// tie-break (smaller feature wins) does not depend on the binned ranking; {0} when empty.
std::vector<std::size_t> refineOrder(const std::vector<SplitCandidate>& candidates);

// Best binned splits over the whole matrix, best first (gain descending, feature ascending).
// Samples [0, positives) are positives, the rest negatives: the trainer orders them so, which
// lets the histogram loop add one weight per sample without looking at a label.
std::vector<SplitCandidate> bestBinnedSplits(const FeatureMatrix& m, std::size_t positives,
                                             std::span<const float> weights, std::size_t k,
                                             int threads = 0);

// Exact weighted least-squares stump of one feature from its raw values (same sample order).
FittedStump fitStumpExact(std::size_t feature, std::span<const float> values,
                          std::span<const float> weights, std::size_t positives);

// Raw values of one feature for every sample (used for the exact refinement).
using FeatureValuesFn = std::function<void(std::size_t feature, std::span<float> out)>;

struct StumpSearchOptions {
  int threads = 0;            // 0 = all cores
  std::size_t refineTop = 4;  // binned candidates refined exactly
};

// Steps 1 and 2 together. Throws std::invalid_argument on mismatched sizes or an empty matrix.
FittedStump findBestStump(const FeatureMatrix& m, std::size_t positives,
                          std::span<const float> weights, const FeatureValuesFn& rawValues,
                          const StumpSearchOptions& options = {});

// sum_i w_i (y_i - f(x_i))^2 for a stump given the raw values of its feature (y by position).
double stumpSquaredError(const FittedStump& s, std::span<const float> values,
                         std::span<const float> weights, std::size_t positives);

}  // namespace fusedet::boosting
