// SPDX-License-Identifier: Apache-2.0
#pragma once
// IntegralStack: summed-area tables of the layers of one LayerStack that a model reads, built
// once per stack (paper §2). Sums are kept in double: exact for 8- and 16-bit layers (every
// partial sum is an integer below 2^53 up to ~1.4e11 pixels) and for float layers as exact as a
// double sum can be.

#include <cstddef>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

// Summed-area table of one layer: sum(x, y) = sum of data over [0, x) x [0, y); (w+1) x (h+1).
struct LayerIntegral {
  std::string name;
  int width = 0, height = 0;  // the layer's own pixel grid
  std::vector<double> sum;    // (height + 1) rows of stride() values

  std::ptrdiff_t stride() const { return width + 1; }
  // Sum over the pixels [x0, x1) x [y0, y1) (no bounds check: callers clamp).
  double rectSum(int x0, int y0, int x1, int y1) const {
    const std::ptrdiff_t s = stride();
    return sum[y1 * s + x1] - sum[y0 * s + x1] - sum[y1 * s + x0] + sum[y0 * s + x0];
  }
};

// Builds the summed-area table of one single-channel 8U, 16U or 32F image.
LayerIntegral integrateLayer(const std::string& name, const cv::Mat& data);

class IntegralStack {
 public:
  IntegralStack() = default;
  // Integrates `layers` of `stack`, in that order (index i = layers[i]). A layer named
  // "hue_distance" that the stack lacks is derived from its "hue" layer with `referenceHue`
  // (fusedet::hueDistanceLayer). Throws std::out_of_range naming a missing layer and
  // std::invalid_argument when hue_distance is needed without a reference hue.
  IntegralStack(const LayerStack& stack, std::span<const std::string> layers,
                std::optional<double> referenceHue = std::nullopt);

  int width() const { return width_; }    // reference grid of the stack
  int height() const { return height_; }
  std::size_t size() const { return layers_.size(); }
  const LayerIntegral& layer(std::size_t i) const { return layers_.at(i); }

 private:
  std::vector<LayerIntegral> layers_;
  int width_ = 0, height_ = 0;
};

}  // namespace fusedet::boosting
