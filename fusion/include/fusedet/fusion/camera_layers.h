#pragma once
// Camera layers of a stack (paper §3.1): red, green, blue, intensity (8-bit, full resolution) and
// hue (float degrees). hue_distance is per class and derived later (core/hue_distance.h).

#include <opencv2/core/mat.hpp>

#include "fusedet/core/layer_stack.h"

namespace fusedet::fusion {

// Hue of an 8-bit BGR image in degrees [0, 360), CV_32FC1, the HSV hue of OpenCV's float
// conversion (0 where the pixel is grey: max == min).
cv::Mat hueDegrees(const cv::Mat& bgr);

// Adds red, green, blue, intensity (ITU-R BT.601 luma, as cv::COLOR_BGR2GRAY) and hue to `stack`
// and sets its reference size to the image. bgr: CV_8UC3.
void addCameraLayers(LayerStack& stack, const cv::Mat& bgr);

}  // namespace fusedet::fusion
