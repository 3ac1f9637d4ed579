// SPDX-License-Identifier: Apache-2.0
#pragma once
// Feature: one of the ten feature types of the paper (Fig. 1, a-j) on one sensor layer, with its
// rectangle in unit-square window coordinates (paper eq. 1, Fig. 4). Its value on a window is
// mean(black) - mean(white) over the layer's own pixels: zero on constant input, independent of
// the window size and of the layer's resolution.
//
// Black parts: a left half, b top half, c/d middle third, e top-left + bottom-right quadrants,
// f centre cell of a 3x3 grid, g/h/i/j the top-left/top-right/bottom-left/bottom-right quadrant
// (against the other three). White = the rest of the feature rectangle.
//
// Mapping to pixels (the one rule training and detection share): a window placed at a box of the
// stack's reference grid covers, on layer l, an integer window of wl = max(round(w * sx), 3)
// by hl = max(round(h * sy), 3) pixels (sx, sy = layer size / reference size) whose origin is
// round(x * sx), round(y * sy), clamped into the layer. The feature's edges are
// round(rect * window size) inside that window, widened to at least one pixel per grid cell.

#include <array>
#include <cstdint>
#include <span>
#include <string>

#include "fusedet/boost/feature_type.h"
#include "fusedet/boost/integral_stack.h"
#include "fusedet/core/box.h"

namespace fusedet::boosting {

struct Feature {
  FeatureType type = FeatureType::kEdgeHorizontal;
  Box rect;       // unit-square window coordinates, inside [0, 1] x [0, 1], non-empty
  int layer = 0;  // index into Cascade::layers (= the IntegralStack's layer order)

  bool operator==(const Feature&) const = default;
};

// Columns x rows of the type's grid (a: 2x1, b: 1x2, c: 3x1, d: 1x3, e: 2x2, f: 3x3, g-j: 2x2):
// the smallest size in pixels at which every part is non-empty.
std::array<int, 2> featureGrid(FeatureType type);

// Throws std::invalid_argument when the rectangle leaves the unit square, is empty or not finite.
void validateFeature(const Feature& f, std::size_t layerCount);

// A feature laid out on a layer's pixels: black = the sum of rects[0, blackCount); white = the
// next rectangle, or (whiteIsRest) the outer rectangle there minus black. value = black / blackArea
// - white / whiteArea, by division so that constant input gives exactly 0 (flat laser regions
// must not produce rounding noise a stump could split on).
struct PixelRect {
  int x0 = 0, y0 = 0, x1 = 0, y1 = 0;  // [x0, x1) x [y0, y1)
};
struct FeatureLayout {
  std::array<PixelRect, 3> rects{};
  int blackCount = 1;        // 1, or 2 for the checker (e)
  bool whiteIsRest = false;  // rects[blackCount] is the outer rectangle
  double blackArea = 1, whiteArea = 1;
  int count() const { return blackCount + 1; }
};

// Layout of `type` on the outer pixel rectangle `outer` (each grid cell non-empty).
FeatureLayout layoutFeature(FeatureType type, const PixelRect& outer);

// Integer window of one layer for a window box of the reference grid (see the rule above).
struct LayerWindow {
  int x = 0, y = 0, w = 0, h = 0;
};
LayerWindow layerWindow(const LayerIntegral& layer, int refWidth, int refHeight, const Box& window);
// Window size alone (per scale) and origin alone (per position), as the scanner precomputes them.
std::array<int, 2> layerWindowSize(const LayerIntegral& layer, int refWidth, int refHeight,
                                   double windowW, double windowH);
// Outer pixel rectangle of a feature relative to the origin of a layer window of size w x h.
PixelRect featureRectInWindow(const Feature& f, int w, int h);

// Value of `f` on the window `window` (reference pixels) of `integrals`. Computed in double from
// the exact sums and rounded to float: the precision stumps compare in (training and detection).
float featureValue(const IntegralStack& integrals, const Feature& f, const Box& window);

// Values of many features on one window (same result as featureValue for each).
void featureValues(const IntegralStack& integrals, std::span<const Feature> features,
                   const Box& window, std::span<float> out);

std::string describe(const Feature& f);  // e.g. "g [0.1 0.2 0.5 0.4] layer 3"

}  // namespace fusedet::boosting
