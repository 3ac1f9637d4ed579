// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/integral_stack.h"

#include <stdexcept>

#include "fusedet/core/hue_distance.h"

namespace fusedet::boosting {

namespace {

template <class T>
void integrate(const cv::Mat& data, LayerIntegral& out) {
  const int w = data.cols, h = data.rows;
  const std::ptrdiff_t s = out.stride();
  double* sum = out.sum.data();
  for (int y = 0; y < h; ++y) {
    const T* row = data.ptr<T>(y);
    double* prev = sum + y * s;
    double* cur = prev + s;
    double rowSum = 0;
    for (int x = 0; x < w; ++x) {
      rowSum += static_cast<double>(row[x]);
      cur[x + 1] = prev[x + 1] + rowSum;
    }
  }
}

}  // namespace

LayerIntegral integrateLayer(const std::string& name, const cv::Mat& data) {
  if (data.channels() != 1 || data.empty())
    throw std::invalid_argument("integrateLayer: layer '" + name + "' must be a non-empty single-channel image");
  LayerIntegral out;
  out.name = name;
  out.width = data.cols;
  out.height = data.rows;
  const std::size_t n = static_cast<std::size_t>(data.cols + 1) * static_cast<std::size_t>(data.rows + 1);
  out.sum.assign(n, 0.0);
  switch (data.depth()) {
    case CV_8U: integrate<std::uint8_t>(data, out); break;
    case CV_16U: integrate<std::uint16_t>(data, out); break;
    case CV_32F: integrate<float>(data, out); break;
    case CV_64F: integrate<double>(data, out); break;
    default:
      throw std::invalid_argument("integrateLayer: layer '" + name + "' must be 8U, 16U, 32F or 64F");
  }
  return out;
}

IntegralStack::IntegralStack(const LayerStack& stack, std::span<const std::string> layers,
                             std::optional<double> referenceHue)
    : width_(stack.width()), height_(stack.height()) {
  if (width_ <= 0 || height_ <= 0)
    throw std::invalid_argument("IntegralStack: stack has no reference size");
  layers_.reserve(layers.size());
  for (const std::string& name : layers) {
    const Layer* l = stack.find(name);
    if (!l && name == layer::kHueDistance && stack.has(layer::kHue)) {
      if (!referenceHue)
        throw std::invalid_argument("IntegralStack: layer 'hue_distance' needs a reference hue");
      const Layer& hueLayer = stack.at(layer::kHue);
      cv::Mat hue = hueLayer.data;
      if (hue.type() != CV_32FC1) hue.convertTo(hue, CV_32F);
      layers_.push_back(integrateLayer(name, hueDistanceLayer(hue, hueLayer.valid, *referenceHue)));
      continue;
    }
    if (!l) stack.at(name);  // throws, naming the missing layer and the ones present
    layers_.push_back(integrateLayer(name, l->data));
  }
}

}  // namespace fusedet::boosting
