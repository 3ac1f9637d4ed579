// SPDX-License-Identifier: Apache-2.0
#pragma once
// Box: an axis-aligned rectangle (x, y = top-left corner). Used in pixels and in unit-square
// coordinates (paper eq. 1), the unit depending on the context the box lives in.

#include <algorithm>

namespace fusedet {

struct Box {
  double x = 0, y = 0, w = 0, h = 0;

  double area() const { return std::max(0.0, w) * std::max(0.0, h); }
  double right() const { return x + w; }
  double bottom() const { return y + h; }
  double centerX() const { return x + w / 2; }
  double centerY() const { return y + h / 2; }
  bool operator==(const Box&) const = default;
};

double intersectionArea(const Box& a, const Box& b);
double iou(const Box& a, const Box& b);  // 0 when both are empty
// Share of `a` covered by `b` (intersection / area(a)); used for ignore regions.
double coverage(const Box& a, const Box& b);

}  // namespace fusedet
