// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/feature_layers.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace fusedet::fusion {

std::vector<int> chooseFeatureChannels(const cv::Mat& headWeights, int fieldsPerAnchor, int count) {
  if (headWeights.type() != CV_32F || headWeights.dims < 2 || fieldsPerAnchor < 5)
    throw std::invalid_argument(
        "feature channels: the head's weights are not a float outputs x channels blob");
  const int outputs = headWeights.size[0];
  const int channels = static_cast<int>(headWeights.total() / static_cast<std::size_t>(outputs));
  if (outputs % fieldsPerAnchor != 0)
    throw std::invalid_argument("feature channels: the head has " + std::to_string(outputs) +
                                " outputs, not a whole number of anchors of " +
                                std::to_string(fieldsPerAnchor));
  if (count < 1 || count > channels)
    throw std::invalid_argument("feature channels: " + std::to_string(count) + " of " +
                                std::to_string(channels) + " channels asked");
  std::vector<double> weight(static_cast<std::size_t>(channels), 0.0);
  const float* w = headWeights.ptr<float>();
  for (int a = 0; a < outputs / fieldsPerAnchor; ++a) {
    const float* objectness = w + static_cast<std::size_t>(a * fieldsPerAnchor + 4) * channels;
    for (int c = 0; c < channels; ++c) weight[static_cast<std::size_t>(c)] += std::abs(objectness[c]);
  }
  std::vector<int> order(static_cast<std::size_t>(channels));
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](int x, int y) {
    return weight[static_cast<std::size_t>(x)] > weight[static_cast<std::size_t>(y)];
  });
  order.resize(static_cast<std::size_t>(count));
  return order;
}

std::string featureLayerName(int rank) {
  return "neural_feature_" + std::to_string(rank);
}

cv::Mat featureMap(const cv::Mat& tap, int channel, const InputGeometry& g, int gridWidth, int gridHeight) {
  if (gridWidth < 1 || gridHeight < 1 || g.image.width < 1 || g.image.height < 1)
    throw std::invalid_argument("feature map: empty grid or image");
  if (tap.dims != 4 || tap.size[0] != 1 || tap.type() != CV_32F || channel < 0 || channel >= tap.size[1])
    throw std::invalid_argument(
        "feature map: channel " + std::to_string(channel) + " of a tap blob that has " +
        (tap.dims == 4 ? std::to_string(tap.size[1]) : std::string("no")) + " channels");
  const int h = tap.size[2], w = tap.size[3];
  const float* plane = tap.ptr<float>(0, channel);
  // A cell's centre in image pixels -> input pixels -> feature cells (cell i's centre at i + 0.5),
  // clamped to the outer cells' centres; bilinear between the four nearest centres.
  const double strideX = double(g.input.width) / w, strideY = double(g.input.height) / h;
  struct Tap {
    int i0, i1;
    float t;  // weight of i1
  };
  const auto taps = [](int cells, int size, int imageSize, double scale, int pad, double stride) {
    std::vector<Tap> out(static_cast<std::size_t>(cells));
    for (int i = 0; i < cells; ++i) {
      const double image = (i + 0.5) * imageSize / cells;
      const double u = std::clamp((image * scale + pad) / stride - 0.5, 0.0, double(size - 1));
      const int i0 = std::min(static_cast<int>(u), size - 1);
      out[static_cast<std::size_t>(i)] = {i0, std::min(i0 + 1, size - 1), static_cast<float>(u - i0)};
    }
    return out;
  };
  const std::vector<Tap> xs = taps(gridWidth, w, g.image.width, g.scaleX, g.padX, strideX);
  const std::vector<Tap> ys = taps(gridHeight, h, g.image.height, g.scaleY, g.padY, strideY);
  cv::Mat out(gridHeight, gridWidth, CV_32F);
  for (int y = 0; y < gridHeight; ++y) {
    const Tap& ty = ys[static_cast<std::size_t>(y)];
    const float* r0 = plane + static_cast<std::size_t>(ty.i0) * w;
    const float* r1 = plane + static_cast<std::size_t>(ty.i1) * w;
    float* row = out.ptr<float>(y);
    for (int x = 0; x < gridWidth; ++x) {
      const Tap& tx = xs[static_cast<std::size_t>(x)];
      const float top = r0[tx.i0] + tx.t * (r0[tx.i1] - r0[tx.i0]);
      const float bottom = r1[tx.i0] + tx.t * (r1[tx.i1] - r1[tx.i0]);
      row[x] = top + ty.t * (bottom - top);
    }
  }
  return out;
}

void addFeatureLayers(LayerStack& stack, const cv::Mat& tap, const std::vector<int>& channels,
                      const InputGeometry& geometry, double scale) {
  if (stack.width() < 1 || stack.height() < 1)
    throw std::invalid_argument("neural feature layers: the stack has no reference size");
  if (!(scale > 0)) throw std::invalid_argument("neural feature layers: scale must be > 0");
  const int gw = std::max(1, static_cast<int>(std::lround(stack.width() * scale)));
  const int gh = std::max(1, static_cast<int>(std::lround(stack.height() * scale)));
  for (std::size_t rank = 0; rank < channels.size(); ++rank)
    stack.set(Layer{
        featureLayerName(static_cast<int>(rank)), featureMap(tap, channels[rank], geometry, gw, gh), {}});
}

}  // namespace fusedet::fusion
