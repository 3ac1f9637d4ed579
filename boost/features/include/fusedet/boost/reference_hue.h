// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-class reference hue for the hue-distance layer (paper §3.1, Fig. 5), from coarse additive
// histograms of 36 bins of 10 degrees, smoothed over neighbouring bins (circularly). Only pixels
// that carry a hue count (the hue layer's mask: grey and dark pixels have none). The paper's rule
// is the most frequent hue inside the positive boxes (referenceHue()); on street scenes that is
// the same bluish grey for every class, so training uses the class's *distinctive* hue
// (distinctiveHue()): the bin most over-represented inside the positives relative to the whole
// training images. Stored in the model; detection derives hue_distance = angular distance to it
// (core/hue_distance.h).

#include <array>
#include <vector>

#include "fusedet/core/box.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

inline constexpr int kHueBins = 36;  // 10 degrees each

class HueHistogram {
 public:
  // Adds every valid pixel of the stack's "hue" layer inside `box` (reference pixels).
  // Throws std::out_of_range when the stack has no hue layer.
  void add(const LayerStack& stack, const Box& box);
  void addHue(double hueDeg, double weight = 1.0);

  const std::array<double, kHueBins>& bins() const { return bins_; }
  // Circular [1 2 1] / 4 smoothing of the bins.
  std::array<double, kHueBins> smoothed() const;
  // Centre of the argmax bin of the smoothed histogram, in degrees (5, 15, ..., 355); ties go to
  // the lower bin. Throws std::runtime_error when nothing was added.
  double referenceHue() const;
  // Centre of the bin maximising share(class) / (share(background) + 0.001) among bins holding
  // at least minShare of the class's (smoothed) pixels; ties go to the lower bin. Throws
  // std::runtime_error when either histogram is empty.
  double distinctiveHue(const HueHistogram& background, double minShare = 0.03) const;
  // Adds every `stride`-th valid hue pixel (in both directions) of the whole stack.
  void addImage(const LayerStack& stack, int stride = 4);
  double total() const { return total_; }

 private:
  std::array<double, kHueBins> bins_{};
  double total_ = 0;
};

}  // namespace fusedet::boosting
