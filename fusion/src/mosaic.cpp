#include "fusedet/fusion/mosaic.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#include "fusedet/core/hue_distance.h"

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

void dashedRect(cv::Mat& img, const cv::Rect& r, const cv::Scalar& colour) {
  const cv::Point c[4] = {r.tl(), {r.x + r.width, r.y}, r.br(), {r.x, r.y + r.height}};
  for (int side = 0; side < 4; ++side) {
    const cv::Point a = c[side], b = c[(side + 1) % 4];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    for (double t = 0; t < len; t += 12) {
      const double t1 = std::min(len, t + 6);
      cv::line(img, a + (b - a) * (t / len), a + (b - a) * (t1 / len), colour, 1, cv::LINE_AA);
    }
  }
}

void drawBoxes(cv::Mat& tile, double scale, const Labels& labels, const std::vector<Detection>& detections) {
  const auto rect = [scale](const Box& b) {
    return cv::Rect(cvRound(b.x * scale), cvRound(b.y * scale), cvRound(b.w * scale), cvRound(b.h * scale));
  };
  for (const Label& l : labels) {
    if (l.ignore) {
      dashedRect(tile, rect(l.box), cv::Scalar(170, 170, 170));
      continue;
    }
    const cv::Scalar colour = l.className == "van" ? cv::Scalar(0, 165, 255) : cv::Scalar(0, 220, 0);
    const cv::Rect r = rect(l.box);
    cv::rectangle(tile, r, colour, 2);
    cv::putText(tile, l.className, r.tl() + cv::Point(2, 14), cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv::LINE_AA);
  }
  for (const Detection& d : detections) {
    const cv::Rect r = rect(d.box);
    cv::rectangle(tile, r, cv::Scalar(0, 0, 255), 2);
    char text[96];
    std::snprintf(text, sizeof text, "%s %.2f", d.className.c_str(), d.score);
    cv::putText(tile, text, cv::Point(r.x + 2, r.y + r.height - 4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
  }
}
}  // namespace

cv::Mat renderMosaic(const LayerStack& stack, const Labels& labels, const std::vector<Detection>& detections,
                     const MosaicOptions& o) {
  if (stack.size() == 0 || stack.width() <= 0 || stack.height() <= 0)
    throw std::invalid_argument("renderMosaic: empty stack");
  if (o.columns < 1 || !(o.scale > 0 && o.scale <= 4)) throw std::invalid_argument("renderMosaic: bad options");
  const cv::Size tileSize(std::max(1, cvRound(stack.width() * o.scale)), std::max(1, cvRound(stack.height() * o.scale)));

  std::vector<std::pair<std::string, cv::Mat>> tiles;  // caption, BGR at layer size
  const Layer *r = stack.find(layer::kRed), *g = stack.find(layer::kGreen), *b = stack.find(layer::kBlue);
  if (o.colourTile && r && g && b && r->data.depth() == CV_8U && r->data.size() == g->data.size() &&
      r->data.size() == b->data.size() && g->data.depth() == CV_8U && b->data.depth() == CV_8U) {
    cv::Mat bgr;
    cv::merge(std::vector<cv::Mat>{b->data, g->data, r->data}, bgr);
    tiles.emplace_back("colour", bgr);
  }
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
