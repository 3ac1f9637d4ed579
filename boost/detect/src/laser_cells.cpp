// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/laser_cells.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace fusedet::boosting {

namespace {
constexpr double kBandTop = 0.35, kBandBottom = 0.85;  // rows of the band, fractions of the box's height
}  // namespace

LaserCells::LaserCells(const LayerStack& stack) {
  if (stack.width() <= 0 || stack.height() <= 0) return;
  const Layer* layer = stack.find(layer::kDistance);
  if (!layer || layer->data.empty()) return;
  if (layer->data.type() == CV_32F)
    d_ = layer->data;  // shares the layer's cells
  else
    layer->data.convertTo(d_, CV_32F);
  mask_ = layer->valid;
  sx_ = double(d_.cols) / stack.width();
  sy_ = double(d_.rows) / stack.height();
}

int LaserCells::col(double x) const { return std::clamp(static_cast<int>(std::floor(x)), 0, d_.cols - 1); }
int LaserCells::row(double y) const { return std::clamp(static_cast<int>(std::floor(y)), 0, d_.rows - 1); }

LaserCells::Place LaserCells::place(const Box& box) const {
  Place p;
  p.x0 = box.x * sx_;
  p.x1 = box.right() * sx_;
  p.y0 = box.y * sy_;
  p.h = box.h * sy_;
  p.bandTop = row(p.y0 + kBandTop * p.h);
  p.bandEnd = row(p.y0 + kBandBottom * p.h) + 1;
  p.coreFirst = col(p.x0 + 0.25 * p.width());
  p.coreLast = col(p.x1 - 0.25 * p.width());
  return p;
}

std::optional<double> LaserCells::coreDepth(const Place& at, int minCells) const {
  if (empty()) return std::nullopt;
  std::vector<float> core;
  for (int r = at.bandTop; r < at.bandEnd; ++r)
    for (int c = at.coreFirst; c <= at.coreLast; ++c)
      if (valid(r, c)) core.push_back(d_(r, c));
  if (static_cast<int>(core.size()) < std::max(1, minCells)) return std::nullopt;
  std::nth_element(core.begin(), core.begin() + static_cast<std::ptrdiff_t>(core.size() / 2), core.end());
  return core[core.size() / 2];
}

}  // namespace fusedet::boosting
