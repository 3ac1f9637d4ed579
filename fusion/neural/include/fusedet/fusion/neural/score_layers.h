// SPDX-License-Identifier: Apache-2.0
#pragma once
// Per-class score maps of a detector network as layers of a stack, named `neural_<class>`, that
// the joint feature pool reads like any other layer (float, [0, 1], no mask).
//
// Rule: a cell of the layer's grid takes the highest score of the class over the anchor rows
// whose box covers the cell's centre (box.x <= cx < box.x + box.w, likewise y; the centre in the
// stack's reference pixels), 0 where no box covers it. Every anchor row counts, before any
// threshold or NMS: a cell keeps what the network thinks of the best object that could contain it,
// so a boosted feature can compare the inside of a window with its surround.

#include <string>
#include <vector>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/neural/anchors.h"

namespace fusedet::fusion {

struct ScoreLayerClass {
  std::string layer;  // "neural_person"
  int classId = 0;    // its column in Anchors::scores (COCO id)
};

// neural_person (COCO 0), neural_bicycle (1), neural_car (2).
const std::vector<ScoreLayerClass>& defaultScoreLayers();

// The score map of class column `classId` on a grid of gridWidth x gridHeight cells over an image
// of imageWidth x imageHeight pixels (the frame the anchors' boxes are in). CV_32FC1. Throws
// std::invalid_argument for an empty grid or image or a class outside the anchors' columns.
cv::Mat scoreMap(const Anchors& anchors, int classId, int imageWidth, int imageHeight, int gridWidth,
                 int gridHeight);

// Adds one layer per class to `stack` on a grid of the stack's reference size times `scale`
// (rounded, at least 1 x 1). The anchors' boxes must be in the stack's reference pixels (the
// network ran on the stack's camera image).
void addScoreLayers(LayerStack& stack, const Anchors& anchors, double scale = 0.5,
                    const std::vector<ScoreLayerClass>& classes = defaultScoreLayers());

}  // namespace fusedet::fusion
