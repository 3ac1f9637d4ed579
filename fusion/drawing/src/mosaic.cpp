// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/drawing/mosaic.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "fusedet/core/hue_distance.h"
#include "fusedet/fusion/camera_layers.h"
#include "fusedet/fusion/drawing/box_drawing.h"

namespace fusedet::fusion {
namespace {
constexpr int kCaption = 24;  // caption bar above each tile [px]

// Valid-range stretch of a float layer to 8 bit; `invert` maps small values to bright.
cv::Mat stretch(const cv::Mat& data, const cv::Mat& valid, bool invert) {
  double lo = 0, hi = 0;
  cv::minMaxLoc(data, &lo, &hi, nullptr, nullptr, valid.empty() ? cv::noArray() : cv::InputArray(valid));
  const double range = hi > lo ? hi - lo : 1.0;
  cv::Mat out;
  if (invert)
    data.convertTo(out, CV_8U, -255.0 / range, 255.0 * hi / range);
  else
    data.convertTo(out, CV_8U, 255.0 / range, -255.0 * lo / range);
  return out;
}

cv::Mat hueColours(const cv::Mat& hueDeg) {
  cv::Mat h, hsv;
  hueDeg.convertTo(h, CV_8U, 0.5);  // OpenCV 8-bit hue is degrees / 2
  cv::Mat full(hueDeg.size(), CV_8UC1, cv::Scalar(255));
  cv::merge(std::vector<cv::Mat>{h, full, full}, hsv);
  cv::Mat bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  return bgr;
}

// One layer as an 8-bit BGR image at the layer's own size.
cv::Mat visualise(const Layer& l) {
  cv::Mat out;
  if (l.name == layer::kHue && l.data.depth() == CV_32F) {
    out = hueColours(l.data);
  } else if (l.data.depth() == CV_8U) {
    cv::cvtColor(l.data, out, cv::COLOR_GRAY2BGR);
  } else {
    cv::Mat f;
    l.data.convertTo(f, CV_32F);
    const bool isDistance = l.name == layer::kDistance;
    cv::Mat g = stretch(f, l.valid, isDistance);
    if (isDistance)
      cv::applyColorMap(g, out, cv::COLORMAP_JET);  // near = red, far = blue
    else
      cv::cvtColor(g, out, cv::COLOR_GRAY2BGR);
  }
  if (l.hasMask()) out.setTo(cv::Scalar(0, 0, 0), l.valid == 0);
  return out;
}

}  // namespace

cv::Mat renderMosaic(const LayerStack& stack, const Labels& labels, const std::vector<Detection>& detections,
                     const MosaicOptions& o) {
  if (stack.size() == 0 || stack.width() <= 0 || stack.height() <= 0)
    throw std::invalid_argument("renderMosaic: empty stack");
  if (o.columns < 1 || !(o.scale > 0 && o.scale <= 4)) throw std::invalid_argument("renderMosaic: bad options");
  const cv::Size tileSize(std::max(1, cvRound(stack.width() * o.scale)), std::max(1, cvRound(stack.height() * o.scale)));

  std::vector<std::pair<std::string, cv::Mat>> tiles;  // caption, BGR at layer size
  if (o.colourTile && hasCameraImage(stack)) tiles.emplace_back("colour", cameraImage(stack));
  for (const Layer& l : stack.layers()) {
    char caption[160];
    const double validShare = l.hasMask() ? static_cast<double>(cv::countNonZero(l.valid)) / static_cast<double>(l.valid.total()) : 1.0;
    std::snprintf(caption, sizeof caption, "%s  %dx%d  valid %.0f%%", l.name.c_str(), l.width(), l.height(), 100 * validShare);
    tiles.emplace_back(caption, visualise(l));
  }
  if (o.hueReference) {
    if (const Layer* hue = stack.find(layer::kHue); hue && hue->data.type() == CV_32FC1) {
      char caption[96];
      std::snprintf(caption, sizeof caption, "hue_distance to %.0f deg", *o.hueReference);
      cv::Mat d = hueDistanceLayer(hue->data, hue->valid, *o.hueReference), g8, bgr;
      d.convertTo(g8, CV_8U, 255.0 / 180.0);
      cv::cvtColor(g8, bgr, cv::COLOR_GRAY2BGR);
      tiles.emplace_back(caption, bgr);
    }
  }

  const int cols = std::min(o.columns, static_cast<int>(tiles.size()));
  const int rows = (static_cast<int>(tiles.size()) + cols - 1) / cols;
  const int cellH = tileSize.height + kCaption;
  cv::Mat mosaic(rows * cellH, cols * tileSize.width, CV_8UC3, cv::Scalar(40, 40, 40));
  for (std::size_t i = 0; i < tiles.size(); ++i) {
    const int col = static_cast<int>(i) % cols, row = static_cast<int>(i) / cols;
    cv::Mat tile;
    cv::resize(tiles[i].second, tile, tileSize, 0, 0, cv::INTER_NEAREST);  // laser cells stay visible
    drawBoxes(tile, o.scale, labels, detections);
    tile.copyTo(mosaic(cv::Rect(col * tileSize.width, row * cellH + kCaption, tileSize.width, tileSize.height)));
    cv::putText(mosaic, tiles[i].first, cv::Point(col * tileSize.width + 6, row * cellH + 17),
                cv::FONT_HERSHEY_SIMPLEX, 0.55, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
  }
  return mosaic;
}

}  // namespace fusedet::fusion
