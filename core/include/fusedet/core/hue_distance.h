// SPDX-License-Identifier: Apache-2.0
#pragma once
// Hue distance (paper §3.1): the angular distance between each pixel's hue and a class's
// reference hue, so that hue, an angle, becomes a totally ordered value a Haar feature can use.

#include <opencv2/core/mat.hpp>

namespace fusedet {

// Angular distance in degrees, in [0, 180], of two hues in degrees (any real values; wraps at 360).
double hueDistanceDeg(double hueDeg, double referenceDeg);

// hueDeg: CV_32FC1 hue in degrees [0, 360). Returns CV_32FC1 of the same size, values in [0, 180].
cv::Mat hueDistanceLayer(const cv::Mat& hueDeg, double referenceDeg);

// One row of hueDistanceLayer (the same values): n hues in degrees [0, 360) -> out.
void hueDistanceRow(const float* hueDeg, float* out, int n, double referenceDeg);

// Distance given to pixels without a hue (the hue layer's mask is 0 there): half way between
// "the class's hue" (0) and "the opposite hue" (180), so a grey pixel is neither.
inline constexpr float kNoHueDistance = 90.f;

// hueDistanceLayer with the hue layer's validity mask (CV_8UC1, 0 = no hue; empty = all valid).
cv::Mat hueDistanceLayer(const cv::Mat& hueDeg, const cv::Mat& valid, double referenceDeg);
// One row of it: valid may be null (all valid).
void hueDistanceRow(const float* hueDeg, const unsigned char* valid, float* out, int n, double referenceDeg);

}  // namespace fusedet
