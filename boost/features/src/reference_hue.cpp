// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/reference_hue.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusedet::boosting {

void HueHistogram::addHue(double hueDeg, double weight) {
  if (!std::isfinite(hueDeg)) return;
  double h = std::fmod(hueDeg, 360.0);
  if (h < 0) h += 360.0;
  const int b = std::min(kHueBins - 1, static_cast<int>(h / (360.0 / kHueBins)));
  bins_[b] += weight;
  total_ += weight;
}

void HueHistogram::add(const LayerStack& stack, const Box& box) {
  const Layer& hue = stack.at(layer::kHue);
  const Box px = LayerStack::toLayerPixels(hue, stack.toUnit(box));
  const int x0 = std::clamp(static_cast<int>(std::floor(px.x)), 0, hue.width());
  const int y0 = std::clamp(static_cast<int>(std::floor(px.y)), 0, hue.height());
  const int x1 = std::clamp(static_cast<int>(std::ceil(px.right())), 0, hue.width());
  const int y1 = std::clamp(static_cast<int>(std::ceil(px.bottom())), 0, hue.height());
  if (x1 <= x0 || y1 <= y0) return;
  cv::Mat h;
  hue.data(cv::Rect(x0, y0, x1 - x0, y1 - y0)).convertTo(h, CV_64F);
  for (int y = y0; y < y1; ++y)
    for (int x = x0; x < x1; ++x) {
      if (hue.hasMask() && !hue.valid.at<std::uint8_t>(y, x)) continue;
      addHue(h.at<double>(y - y0, x - x0));
    }
}

std::array<double, kHueBins> HueHistogram::smoothed() const {
  std::array<double, kHueBins> s{};
  for (int b = 0; b < kHueBins; ++b)
    s[b] = (bins_[(b + kHueBins - 1) % kHueBins] + 2 * bins_[b] + bins_[(b + 1) % kHueBins]) / 4;
  return s;
}

double HueHistogram::referenceHue() const {
  if (total_ <= 0) throw std::runtime_error("reference hue: no hue values inside the positive boxes");
  const auto s = smoothed();
  const int best = static_cast<int>(std::max_element(s.begin(), s.end()) - s.begin());
  return (best + 0.5) * (360.0 / kHueBins);
}

double HueHistogram::distinctiveHue(const HueHistogram& background, double minShare) const {
  if (total_ <= 0) throw std::runtime_error("reference hue: no hue values inside the positive boxes");
  if (background.total() <= 0) throw std::runtime_error("reference hue: no hue values in the training images");
  const auto c = smoothed(), b = background.smoothed();
  int best = -1;
  double bestRatio = 0;
  for (int i = 0; i < kHueBins; ++i) {
    const double share = c[i] / total_;
    if (share < minShare) continue;
    const double ratio = share / (b[i] / background.total() + 1e-3);
    if (best < 0 || ratio > bestRatio) best = i, bestRatio = ratio;
  }
  if (best < 0) return referenceHue();  // no bin holds minShare: spread evenly, take the mode
  return (best + 0.5) * (360.0 / kHueBins);
}

void HueHistogram::addImage(const LayerStack& stack, int stride) {
  const Layer& hue = stack.at(layer::kHue);
  const int s = std::max(1, stride);
  cv::Mat h;
  hue.data.convertTo(h, CV_64F);
  for (int y = 0; y < hue.height(); y += s)
    for (int x = 0; x < hue.width(); x += s) {
      if (hue.hasMask() && !hue.valid.at<std::uint8_t>(y, x)) continue;
      addHue(h.at<double>(y, x));
    }
}

}  // namespace fusedet::boosting
