// SPDX-License-Identifier: Apache-2.0
#pragma once
// How an image becomes a detector network's input, and back (facts of ../shared/models/SOURCE.md):
//  - letterbox (YOLOv5): one scale r = min(W / w, H / h) for both axes, the scaled image centred
//    in the W x H input (pad left = (W - round(w r)) / 2, top = (H - round(h r)) / 2, integer
//    division), the rest grey 114;
//  - plain resize (Darknet): the image stretched to W x H, no padding.
// An input pixel p maps to the image pixel (p - pad) / scale on each axis.

#include <opencv2/core/mat.hpp>

#include "fusedet/core/box.h"

namespace fusedet::fusion {

struct InputGeometry {
  cv::Size image;  // the image the network saw
  cv::Size input;  // the network's input W x H
  double scaleX = 1, scaleY = 1;  // input pixels per image pixel
  int padX = 0, padY = 0;         // input pixels left of / above the scaled image

  // A box in input pixels -> the same box in image pixels.
  Box toImage(const Box& inputBox) const;
};

InputGeometry letterboxGeometry(cv::Size image, cv::Size input);
InputGeometry resizeGeometry(cv::Size image, cv::Size input);

// The W x H input image (8-bit BGR, like `bgr`) by `geometry`: the image resized (bilinear) to its
// scaled size and placed at the pad, the rest grey 114.
cv::Mat makeInputImage(const cv::Mat& bgr, const InputGeometry& geometry);

}  // namespace fusedet::fusion
