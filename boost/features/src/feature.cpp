// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/feature.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace fusedet::boosting {

namespace {

int roundHalfUp(double v) { return static_cast<int>(std::floor(v + 0.5)); }

// Split point at fraction num/den of [a, b), keeping at least `before` pixels before it and
// `after` pixels after it.
int splitAt(int a, int b, int num, int den, int before, int after) {
  const int len = b - a;
  const int p = roundHalfUp(double(len) * num / den);
  return a + std::clamp(p, before, len - after);
}

double area(const PixelRect& r) { return double(r.x1 - r.x0) * double(r.y1 - r.y0); }

FeatureLayout blackVsRest(const PixelRect& outer, const PixelRect& black) {
  FeatureLayout l;
  l.rects[0] = black;
  l.rects[1] = outer;
  l.whiteIsRest = true;
  l.blackArea = area(black);
  l.whiteArea = area(outer) - l.blackArea;
  return l;
}

// Two disjoint halves covering outer: black first.
FeatureLayout halves(const PixelRect& black, const PixelRect& white) {
  FeatureLayout l;
  l.rects[0] = black;
  l.rects[1] = white;
  l.blackArea = area(black);
  l.whiteArea = area(white);
  return l;
}

}  // namespace

std::array<int, 2> featureGrid(FeatureType type) {
  switch (type) {
    case FeatureType::kEdgeHorizontal: return {2, 1};
    case FeatureType::kEdgeVertical: return {1, 2};
    case FeatureType::kLineHorizontal: return {3, 1};
    case FeatureType::kLineVertical: return {1, 3};
    case FeatureType::kCenterSurround: return {3, 3};
    default: return {2, 2};  // checker and corners
  }
}

void validateFeature(const Feature& f, std::size_t layerCount) {
  const Box& r = f.rect;
  const bool finite = std::isfinite(r.x) && std::isfinite(r.y) && std::isfinite(r.w) && std::isfinite(r.h);
  constexpr double kSlack = 1e-9;  // rectangles written with finite decimals may end at 1 + eps
  if (!finite || r.w <= 0 || r.h <= 0 || r.x < -kSlack || r.y < -kSlack || r.right() > 1 + kSlack ||
      r.bottom() > 1 + kSlack)
    throw std::invalid_argument("feature " + describe(f) + ": rectangle must be non-empty and inside the unit square");
  if (static_cast<std::size_t>(static_cast<unsigned>(static_cast<int>(f.type))) >= kFeatureTypeCount)
    throw std::invalid_argument("feature " + describe(f) + ": unknown feature type");
  if (f.layer < 0 || static_cast<std::size_t>(f.layer) >= layerCount)
    throw std::invalid_argument("feature " + describe(f) + ": layer index out of range (model has " +
                                std::to_string(layerCount) + " layers)");
}

FeatureLayout layoutFeature(FeatureType type, const PixelRect& o) {
  switch (type) {
    case FeatureType::kEdgeHorizontal: {
      const int xm = splitAt(o.x0, o.x1, 1, 2, 1, 1);
      return halves({o.x0, o.y0, xm, o.y1}, {xm, o.y0, o.x1, o.y1});
    }
    case FeatureType::kEdgeVertical: {
      const int ym = splitAt(o.y0, o.y1, 1, 2, 1, 1);
      return halves({o.x0, o.y0, o.x1, ym}, {o.x0, ym, o.x1, o.y1});
    }
    case FeatureType::kLineHorizontal: {
      const int xa = splitAt(o.x0, o.x1, 1, 3, 1, 2);
      const int xb = splitAt(xa, o.x1, 1, 2, 1, 1);
      return blackVsRest(o, {xa, o.y0, xb, o.y1});
    }
    case FeatureType::kLineVertical: {
      const int ya = splitAt(o.y0, o.y1, 1, 3, 1, 2);
      const int yb = splitAt(ya, o.y1, 1, 2, 1, 1);
      return blackVsRest(o, {o.x0, ya, o.x1, yb});
    }
    case FeatureType::kCenterSurround: {
      const int xa = splitAt(o.x0, o.x1, 1, 3, 1, 2), xb = splitAt(xa, o.x1, 1, 2, 1, 1);
      const int ya = splitAt(o.y0, o.y1, 1, 3, 1, 2), yb = splitAt(ya, o.y1, 1, 2, 1, 1);
      return blackVsRest(o, {xa, ya, xb, yb});
    }
    case FeatureType::kChecker: {
      const int xm = splitAt(o.x0, o.x1, 1, 2, 1, 1), ym = splitAt(o.y0, o.y1, 1, 2, 1, 1);
      const PixelRect tl{o.x0, o.y0, xm, ym}, br{xm, ym, o.x1, o.y1};
      FeatureLayout l;
      l.rects = {tl, br, o};
      l.blackCount = 2;
      l.whiteIsRest = true;
      l.blackArea = area(tl) + area(br);
      l.whiteArea = area(o) - l.blackArea;
      return l;
    }
    default: {  // corners g-j
      const int xm = splitAt(o.x0, o.x1, 1, 2, 1, 1), ym = splitAt(o.y0, o.y1, 1, 2, 1, 1);
      const bool left = type == FeatureType::kCornerTopLeft || type == FeatureType::kCornerBottomLeft;
      const bool top = type == FeatureType::kCornerTopLeft || type == FeatureType::kCornerTopRight;
      const PixelRect q{left ? o.x0 : xm, top ? o.y0 : ym, left ? xm : o.x1, top ? ym : o.y1};
      return blackVsRest(o, q);
    }
  }
}

std::array<int, 2> layerWindowSize(const LayerIntegral& layer, int refWidth, int refHeight,
                                   double windowW, double windowH) {
  if (layer.width < 3 || layer.height < 3)
    throw std::invalid_argument("layer '" + layer.name + "' is smaller than 3x3 pixels");
  const double sx = double(layer.width) / refWidth, sy = double(layer.height) / refHeight;
  const int w = std::clamp(roundHalfUp(windowW * sx), 3, layer.width);
  const int h = std::clamp(roundHalfUp(windowH * sy), 3, layer.height);
  return {w, h};
}

LayerWindow layerWindow(const LayerIntegral& layer, int refWidth, int refHeight, const Box& window) {
  const auto [w, h] = layerWindowSize(layer, refWidth, refHeight, window.w, window.h);
  const double sx = double(layer.width) / refWidth, sy = double(layer.height) / refHeight;
  const int x = std::clamp(roundHalfUp(window.x * sx), 0, layer.width - w);
  const int y = std::clamp(roundHalfUp(window.y * sy), 0, layer.height - h);
  return {x, y, w, h};
}

PixelRect featureRectInWindow(const Feature& f, int w, int h) {
  const auto [cols, rows] = featureGrid(f.type);
  auto edges = [](double a, double len, int size, int cells, int& e0, int& e1) {
    e0 = std::clamp(roundHalfUp(a * size), 0, size);
    e1 = std::clamp(roundHalfUp((a + len) * size), 0, size);
    if (e1 - e0 < cells) {
      e1 = e0 + cells;
      if (e1 > size) {
        e1 = size;
        e0 = size - cells;
      }
    }
  };
  PixelRect r;
  edges(f.rect.x, f.rect.w, w, cols, r.x0, r.x1);
  edges(f.rect.y, f.rect.h, h, rows, r.y0, r.y1);
  return r;
}

float featureValue(const IntegralStack& integrals, const Feature& f, const Box& window) {
  const LayerIntegral& li = integrals.layer(static_cast<std::size_t>(f.layer));
  const LayerWindow lw = layerWindow(li, integrals.width(), integrals.height(), window);
  PixelRect o = featureRectInWindow(f, lw.w, lw.h);
  o.x0 += lw.x;
  o.x1 += lw.x;
  o.y0 += lw.y;
  o.y1 += lw.y;
  const FeatureLayout l = layoutFeature(f.type, o);
  auto rs = [&](int i) {
    const PixelRect& r = l.rects[static_cast<std::size_t>(i)];
    return li.rectSum(r.x0, r.y0, r.x1, r.y1);
  };
  const double black = l.blackCount == 2 ? rs(0) + rs(1) : rs(0);
  const double last = rs(l.blackCount);
  const double white = l.whiteIsRest ? last - black : last;
  return static_cast<float>(black / l.blackArea - white / l.whiteArea);
}

void featureValues(const IntegralStack& integrals, std::span<const Feature> features,
                   const Box& window, std::span<float> out) {
  if (out.size() < features.size()) throw std::invalid_argument("featureValues: output too small");
  for (std::size_t i = 0; i < features.size(); ++i) out[i] = featureValue(integrals, features[i], window);
}

std::string describe(const Feature& f) {
  char buf[128];
  const int t = static_cast<int>(f.type);
  const char letter = (t >= 0 && t < int(kFeatureTypeCount)) ? toLetter(f.type) : '?';
  std::snprintf(buf, sizeof buf, "%c [%g %g %g %g] layer %d", letter, f.rect.x, f.rect.y, f.rect.w,
                f.rect.h, f.layer);
  return buf;
}

}  // namespace fusedet::boosting
