#include "fusedet/core/hue_distance.h"

#include <cmath>
#include <stdexcept>

namespace fusedet {

double hueDistanceDeg(double hueDeg, double referenceDeg) {
  double d = std::fmod(std::fabs(hueDeg - referenceDeg), 360.0);
  return d > 180.0 ? 360.0 - d : d;
}

void hueDistanceRow(const float* in, float* o, int n, double referenceDeg) {
  const auto ref = static_cast<float>(std::fmod(std::fmod(referenceDeg, 360.0) + 360.0, 360.0));
  for (int x = 0; x < n; ++x) {
    // Both in [0, 360): |h - ref| < 360, so one fold is enough.
    const float d = std::fabs(in[x] - ref);
    o[x] = d > 180.f ? 360.f - d : d;
  }
}

void hueDistanceRow(const float* in, const unsigned char* valid, float* o, int n, double referenceDeg) {
  hueDistanceRow(in, o, n, referenceDeg);
  if (valid)
    for (int x = 0; x < n; ++x)
      if (!valid[x]) o[x] = kNoHueDistance;
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
