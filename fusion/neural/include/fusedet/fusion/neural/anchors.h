// SPDX-License-Identifier: Apache-2.0
#pragma once
// Decoding a YOLO network's raw output into anchor rows in image pixels with per-class scores
// (conventions of ../shared/models/SOURCE.md). Every row is kept: no score threshold, no NMS.
//  - YOLOv5 (ONNX): one 1 x N x (5 + C) output; per row cx, cy, w, h in input pixels, objectness,
//    C class probabilities (after the sigmoid); score = objectness x class probability.
//  - Darknet (YOLO layers through cv::dnn): one M x (5 + C) matrix per output layer, rows in
//    output order; cx, cy, w, h normalised to the input, objectness, C class scores that already
//    include objectness (cv::dnn leaves 0 where a score is below its layer's threshold): taken as
//    they are.
// Boxes leave the input through InputGeometry::toImage (the letterbox or resize undone) and are
// not clipped to the image.

#include <cstddef>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "fusedet/core/box.h"
#include "fusedet/fusion/neural/input_geometry.h"

namespace fusedet::fusion {

struct Anchors {
  std::vector<Box> boxes;         // image pixels, one per row
  std::vector<float> objectness;  // one per row
  cv::Mat scores;                 // rows x classes, CV_32F: the score of each class, [0, 1]

  std::size_t size() const { return boxes.size(); }
  int classes() const { return scores.cols; }
};

// Throws std::invalid_argument naming the shape when an output is not rows x (5 + classes) with
// classes >= 1 (or a 1 x rows x (5 + classes) blob for YOLOv5).
Anchors decodeYolov5(const cv::Mat& output, const InputGeometry& geometry);
Anchors decodeDarknet(const std::vector<cv::Mat>& outputs, const InputGeometry& geometry);

}  // namespace fusedet::fusion
