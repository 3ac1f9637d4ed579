// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/hue_distance.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusedet {

double hueDistanceDeg(double hueDeg, double referenceDeg) {
  double d = std::fmod(std::fabs(hueDeg - referenceDeg), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

namespace {

float wrappedReference(double referenceDeg) {
  return static_cast<float>(std::fmod(std::fmod(referenceDeg, 360.0) + 360.0, 360.0));
}

// Both in [0, 360): |h - ref| < 360, so one fold is enough. "d > 180 ? 360 - d : d" is written
// as a minimum - the same value for every d, NaN included (std::min returns its first argument
// unless the second is smaller) - so that the loops below vectorise instead of branching on
// every pixel (hue is noise to a branch predictor; the detector derives this per model and stack).
inline float foldedDistance(float hue, float ref) {
  const float d = std::fabs(hue - ref);
  return std::min(d, 360.f - d);
}

}  // namespace

void hueDistanceRow(const float* in, float* o, int n, double referenceDeg) {
  const float ref = wrappedReference(referenceDeg);
  for (int x = 0; x < n; ++x) o[x] = foldedDistance(in[x], ref);
}

void hueDistanceRow(const float* in, const unsigned char* valid, float* o, int n, double referenceDeg) {
  if (!valid) return hueDistanceRow(in, o, n, referenceDeg);
  const float ref = wrappedReference(referenceDeg);
  for (int x = 0; x < n; ++x) {
    const float d = foldedDistance(in[x], ref);
    o[x] = valid[x] ? d : kNoHueDistance;
  }
}

cv::Mat hueDistanceLayer(const cv::Mat& hueDeg, const cv::Mat& valid, double referenceDeg) {
  if (valid.empty()) return hueDistanceLayer(hueDeg, referenceDeg);
  if (hueDeg.type() != CV_32FC1) throw std::invalid_argument("hueDistanceLayer: hue must be CV_32FC1 degrees");
  if (valid.type() != CV_8UC1 || valid.size() != hueDeg.size())
    throw std::invalid_argument("hueDistanceLayer: mask must be CV_8UC1 of the hue's size");
  cv::Mat out(hueDeg.size(), CV_32FC1);
  for (int y = 0; y < hueDeg.rows; ++y)
    hueDistanceRow(hueDeg.ptr<float>(y), valid.ptr<unsigned char>(y), out.ptr<float>(y), hueDeg.cols, referenceDeg);
  return out;
}

cv::Mat hueDistanceLayer(const cv::Mat& hueDeg, double referenceDeg) {
  if (hueDeg.type() != CV_32FC1) throw std::invalid_argument("hueDistanceLayer: hue must be CV_32FC1 degrees");
  cv::Mat out(hueDeg.size(), CV_32FC1);
  for (int y = 0; y < hueDeg.rows; ++y) hueDistanceRow(hueDeg.ptr<float>(y), out.ptr<float>(y), hueDeg.cols, referenceDeg);
  return out;
}

}  // namespace fusedet
