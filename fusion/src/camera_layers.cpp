// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/camera_layers.h"

#include <algorithm>
#include <array>
#include <opencv2/imgproc.hpp>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::fusion {

cv::Mat hueDegrees(const cv::Mat& bgr) {
  if (bgr.type() != CV_8UC3) throw std::invalid_argument("hueDegrees: image must be 8-bit BGR");
  cv::Mat hue(bgr.size(), CV_32FC1);
  // One pass, no division: 60 / (max - min) from a table of the 255 possible differences.
  // cv::cvtColor would first need a float copy of the whole image.
  static const std::array<float, 256> kSixtyOver = [] {
    std::array<float, 256> t{};
    for (int d = 1; d < 256; ++d) t[static_cast<std::size_t>(d)] = 60.f / static_cast<float>(d);
    return t;
  }();
  for (int y = 0; y < bgr.rows; ++y) {
    const std::uint8_t* p = bgr.ptr<std::uint8_t>(y);
    float* h = hue.ptr<float>(y);
    for (int x = 0; x < bgr.cols; ++x, p += 3) {
      const int b = p[0], g = p[1], r = p[2];
      const int mx = std::max({b, g, r}), mn = std::min({b, g, r});
      const int diff = mx - mn;
      if (diff == 0) {
        h[x] = 0.f;
        continue;
      }
      const float k = kSixtyOver[static_cast<std::size_t>(diff)];
      float v;
      if (mx == r)
        v = static_cast<float>(g - b) * k;
      else if (mx == g)
        v = static_cast<float>(b - r) * k + 120.f;
      else
        v = static_cast<float>(r - g) * k + 240.f;
      if (v < 0.f) v += 360.f;
      h[x] = v >= 360.f ? v - 360.f : v;
    }
  }
  return hue;
}

cv::Mat hueValidMask(const cv::Mat& bgr, const HueMaskRule& rule) {
  if (bgr.type() != CV_8UC3) throw std::invalid_argument("hueValidMask: image must be 8-bit BGR");
  cv::Mat valid(bgr.size(), CV_8UC1);
  for (int y = 0; y < bgr.rows; ++y) {
    const std::uint8_t* p = bgr.ptr<std::uint8_t>(y);
    std::uint8_t* v = valid.ptr<std::uint8_t>(y);
    for (int x = 0; x < bgr.cols; ++x, p += 3) {
      const int mx = std::max({p[0], p[1], p[2]}), mn = std::min({p[0], p[1], p[2]});
      // Saturation (max - min) / max >= minSaturation, without a division.
      const bool coloured = mx >= rule.minValue && double(mx - mn) >= rule.minSaturation * double(mx) && mx > mn;
      v[x] = coloured ? 255 : 0;
    }
  }
  return valid;
}

void addCameraLayers(LayerStack& stack, const cv::Mat& bgr, const HueMaskRule& hueRule) {
  if (bgr.type() != CV_8UC3) throw std::invalid_argument("addCameraLayers: image must be 8-bit BGR");
  stack.setReferenceSize(bgr.cols, bgr.rows);
  cv::Mat channels[3];
  cv::split(bgr, channels);
  cv::Mat gray;
  cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
  stack.set(Layer{std::string(layer::kRed), channels[2], {}});
  stack.set(Layer{std::string(layer::kGreen), channels[1], {}});
  stack.set(Layer{std::string(layer::kBlue), channels[0], {}});
  stack.set(Layer{std::string(layer::kIntensity), gray, {}});
  stack.set(Layer{std::string(layer::kHue), hueDegrees(bgr), hueValidMask(bgr, hueRule)});
}

namespace {

// Why the stack has no camera image, or empty when it has one.
std::string cameraImageProblem(const LayerStack& stack) {
  const Layer* blue = stack.find(layer::kBlue);
  for (const std::string_view name : {layer::kBlue, layer::kGreen, layer::kRed}) {
    const Layer* l = stack.find(name);
    if (!l || l->data.type() != CV_8UC1) return "the stack has no 8-bit '" + std::string(name) + "' layer";
    if (l->data.size() != blue->data.size()) return "the stack's red, green and blue layers differ in size";
  }
  return {};
}

}  // namespace

bool hasCameraImage(const LayerStack& stack) { return cameraImageProblem(stack).empty(); }

cv::Mat cameraImage(const LayerStack& stack) {
  if (const std::string problem = cameraImageProblem(stack); !problem.empty())
    throw std::invalid_argument(problem + ": no camera image");
  cv::Mat bgr;
  cv::merge(std::vector<cv::Mat>{stack.at(layer::kBlue).data, stack.at(layer::kGreen).data, stack.at(layer::kRed).data}, bgr);
  return bgr;
}

}  // namespace fusedet::fusion
