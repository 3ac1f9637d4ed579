// SPDX-License-Identifier: Apache-2.0
#pragma once
// Camera layers of a stack (paper §3.1): red, green, blue, intensity (8-bit, full resolution) and
// hue (float degrees). hue_distance is per class and derived later (core/hue_distance.h).

#include <opencv2/core/mat.hpp>

#include "fusedet/core/layer_stack.h"

namespace fusedet::fusion {

// Hue of an 8-bit BGR image in degrees [0, 360), CV_32FC1, the HSV hue of OpenCV's float
// conversion (0 where the pixel is grey: max == min).
cv::Mat hueDegrees(const cv::Mat& bgr);

// Which pixels carry a hue: grey, dark and washed-out pixels have none worth comparing (their
// hue is noise, and 0 would read as red). HSV saturation (max - min) / max >= minSaturation
// and value max >= minValue (0-255).
struct HueMaskRule {
  double minSaturation = 0.2;
  int minValue = 40;
};
// CV_8UC1: 255 where the pixel has a hue by `rule`, 0 elsewhere.
cv::Mat hueValidMask(const cv::Mat& bgr, const HueMaskRule& rule = {});

// Adds red, green, blue, intensity (ITU-R BT.601 luma, as cv::COLOR_BGR2GRAY) and hue to `stack`
// and sets its reference size to the image. bgr: CV_8UC3. The hue layer's validity mask is
// hueValidMask(bgr, hueRule): hue_distance gives masked pixels the neutral 90 degrees
// (core/hue_distance.h) and the reference hue counts only valid ones.
void addCameraLayers(LayerStack& stack, const cv::Mat& bgr, const HueMaskRule& hueRule = {});

// The camera image back from a stack's red, green and blue layers (the inverse of addCameraLayers
// for the colour): CV_8UC3 BGR at the layers' size, sharing no memory with them.
// hasCameraImage: whether the stack has the three as 8-bit layers of one size; cameraImage throws
// std::invalid_argument naming what is missing when it has not.
bool hasCameraImage(const LayerStack& stack);
cv::Mat cameraImage(const LayerStack& stack);

}  // namespace fusedet::fusion
