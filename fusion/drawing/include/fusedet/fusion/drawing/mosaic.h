// SPDX-License-Identifier: Apache-2.0
#pragma once
// A picture of what the detector sees (like paper Fig. 8): every layer of a stack as one tile,
// scaled to the reference size, with labels and detections drawn on each tile.

#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/core/label.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::fusion {

struct MosaicOptions {
  int columns = 2;                      // tiles per row
  double scale = 1.0;                   // tile size relative to the stack's reference size
  std::optional<double> hueReference;   // adds a hue_distance tile for this reference hue [deg]
  bool colourTile = true;               // first tile: the RGB image (when red/green/blue exist)
};

// Display mapping per layer: 8-bit as grey; hue as its colour (full saturation and value);
// distance with a colour map (near = red, far = blue), invalid cells black; remission and other
// float layers stretched from their valid range to grey; filled (interpolated) laser cells are
// shown like measured ones. Labels and detections as box_drawing.h draws them. Throws
// std::invalid_argument for an empty stack or options out of range.
cv::Mat renderMosaic(const LayerStack& stack, const Labels& labels, const std::vector<Detection>& detections,
                     const MosaicOptions& options = {});

}  // namespace fusedet::fusion
