// SPDX-License-Identifier: Apache-2.0
#pragma once
// Backbone feature channels of a detector network as layers of a stack, `neural_feature_<rank>`
// (issue 30): a learned-from-big-data description any class can use, beside the per-class score
// maps (score_layers.h).
//
// Where: the feature map the network's finest detection head reads (its "tap"): YOLOv5 (v6
// exports) `/model.17/cv3/act/Mul`, 64 channels at stride 8, read by `/model.24/m.0/Conv`;
// Yolo-Fastest-XL `bn_128`, 144 channels at stride 16, read by `conv_129`.
// Which channels: the head's 1x1 convolution scores objectness from the tap; a channel's weight
// for it, |w[a * (5 + classes) + 4, c]| summed over the head's anchors a, says how much the network
// itself reads that channel to tell an object from background, whatever its class. The `count`
// heaviest channels (ties: the lower index) become ranks 0, 1, ... Data-free and deterministic: the
// same network file (its sha256 is in the network's record) gives the same channels.
// Values: the channel sampled bilinearly at each layer cell's centre (image pixel -> input pixel
// by the input geometry -> feature cell; beyond the outer cells' centres their value), float,
// unbounded (activations), no mask.

#include <string>
#include <vector>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/neural/input_geometry.h"

namespace fusedet::fusion {

// Feature channels of the joint pool's configuration with them (`fusedet experiments`).
constexpr int kPoolFeatureChannels = 8;

// The `count` channel indices by the rule above from the head's weights (outputs x channels
// [x 1 x 1], CV_32F) with `fieldsPerAnchor` outputs per anchor (5 + classes). Throws
// std::invalid_argument naming the shape when the outputs are not a whole number of anchors or
// `count` is not in [1, channels].
std::vector<int> chooseFeatureChannels(const cv::Mat& headWeights, int fieldsPerAnchor, int count);

// "neural_feature_<rank>".
std::string featureLayerName(int rank);

// Channel `channel` of the 1 x C x h x w tap blob on a gridWidth x gridHeight grid over the image
// the network saw (geometry.image), CV_32FC1. Throws std::invalid_argument for an empty grid or a
// channel outside the blob.
cv::Mat featureMap(const cv::Mat& tap, int channel, const InputGeometry& geometry, int gridWidth,
                   int gridHeight);

// Adds neural_feature_0 .. neural_feature_<channels.size() - 1> to `stack` on a grid of its
// reference size times `scale` (rounded, at least 1 x 1). The network ran on the stack's camera
// image (geometry.image may be smaller than the reference size: the grid covers the same view).
void addFeatureLayers(LayerStack& stack, const cv::Mat& tap, const std::vector<int>& channels,
                      const InputGeometry& geometry, double scale = 0.5);

}  // namespace fusedet::fusion
