// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/score_layers.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusedet::fusion {

const std::vector<ScoreLayerClass>& defaultScoreLayers() {
  static const std::vector<ScoreLayerClass> classes = {
      {"neural_person", 0}, {"neural_bicycle", 1}, {"neural_car", 2}};
  return classes;
}

cv::Mat scoreMap(const Anchors& anchors, int classId, int imageWidth, int imageHeight, int gridWidth,
                 int gridHeight) {
  if (gridWidth < 1 || gridHeight < 1 || imageWidth < 1 || imageHeight < 1)
    throw std::invalid_argument("score map: empty grid (" + std::to_string(gridWidth) + "x" +
                                std::to_string(gridHeight) + ") or image (" + std::to_string(imageWidth) + "x" +
                                std::to_string(imageHeight) + ")");
  if (classId < 0 || classId >= anchors.classes())
    throw std::invalid_argument("score map: class " + std::to_string(classId) + " is not among the network's " +
                                std::to_string(anchors.classes()) + " classes");
  cv::Mat map(gridHeight, gridWidth, CV_32F, cv::Scalar(0));
  // Cell i's centre is at (i + 0.5) * cellW; it lies in [a, b) when i >= a / cellW - 0.5 and
  // i < b / cellW - 0.5.
  const double cellW = double(imageWidth) / gridWidth, cellH = double(imageHeight) / gridHeight;
  const auto firstCell = [](double edge, double cell) { return static_cast<int>(std::ceil(edge / cell - 0.5)); };
  for (std::size_t r = 0; r < anchors.size(); ++r) {
    const float s = anchors.scores.at<float>(static_cast<int>(r), classId);
    if (!(s > 0)) continue;
    const Box& b = anchors.boxes[r];
    const int x0 = std::max(0, firstCell(b.x, cellW)), x1 = std::min(gridWidth, firstCell(b.right(), cellW));
    const int y0 = std::max(0, firstCell(b.y, cellH)), y1 = std::min(gridHeight, firstCell(b.bottom(), cellH));
    for (int y = y0; y < y1; ++y) {
      float* row = map.ptr<float>(y);
      for (int x = x0; x < x1; ++x) row[x] = std::max(row[x], s);
    }
  }
  return map;
}

void addScoreLayers(LayerStack& stack, const Anchors& anchors, double scale, const std::vector<ScoreLayerClass>& classes) {
  if (stack.width() < 1 || stack.height() < 1)
    throw std::invalid_argument("neural score layers: the stack has no reference size");
  if (!(scale > 0)) throw std::invalid_argument("neural score layers: scale must be > 0");
  const int gw = std::max(1, static_cast<int>(std::lround(stack.width() * scale)));
  const int gh = std::max(1, static_cast<int>(std::lround(stack.height() * scale)));
  for (const ScoreLayerClass& c : classes)
    stack.set(Layer{c.layer, scoreMap(anchors, c.classId, stack.width(), stack.height(), gw, gh), {}});
}

}  // namespace fusedet::fusion
