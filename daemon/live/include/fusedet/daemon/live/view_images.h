// SPDX-License-Identifier: Apache-2.0
#pragma once
// A stack's layers as JPEG images for viewers: the camera image the boxes refer to (the
// undistorted red, green and blue layers) and one layer in false colour.

#include <cstdint>
#include <optional>
#include <vector>

#include "fusedet/core/layer_stack.h"

namespace fusedet::daemon::live {

inline constexpr int kJpegQuality = 80;

// The stack's red, green and blue layers as one JPEG; nothing when one of them is missing.
std::optional<std::vector<std::uint8_t>> colourJpeg(const LayerStack& stack);

// One layer as a JPEG: 8-bit layers as grey values; others scaled from their smallest to their
// largest valid value onto the turbo colour map (blue = near / low, red = far / high); invalid
// pixels black.
std::vector<std::uint8_t> layerJpeg(const Layer& layer);

}  // namespace fusedet::daemon::live
