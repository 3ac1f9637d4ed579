// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/box.h"

namespace fusedet {

double intersectionArea(const Box& a, const Box& b) {
  const double w = std::min(a.right(), b.right()) - std::max(a.x, b.x);
  const double h = std::min(a.bottom(), b.bottom()) - std::max(a.y, b.y);
  return (w > 0 && h > 0) ? w * h : 0.0;
}

double iou(const Box& a, const Box& b) {
  const double inter = intersectionArea(a, b);
  const double uni = a.area() + b.area() - inter;
  return uni > 0 ? inter / uni : 0.0;
}

double coverage(const Box& a, const Box& b) {
  const double area = a.area();
  return area > 0 ? intersectionArea(a, b) / area : 0.0;
}

}  // namespace fusedet
