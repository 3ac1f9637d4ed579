#pragma once
// Per-class reference hue for the hue-distance layer (paper §3.1, Fig. 5): the most frequent hue
// inside the positive boxes, from a coarse additive histogram of 36 bins of 10 degrees, smoothed
// over neighbouring bins (circularly), argmax. Stored in the model; detection derives
// hue_distance = angular distance to it (core/hue_distance.h).

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
  double total() const { return total_; }

 private:
  std::array<double, kHueBins> bins_{};
  double total_ = 0;
};

}  // namespace fusedet::boosting
