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

LaserCells::Place LaserCells::place(const Box& box) const {
  const auto row = [this](double v) { return std::clamp(static_cast<int>(std::floor(v)), 0, d_.rows - 1); };
  Place p;
  p.x0 = box.x * sx_;
  p.x1 = box.right() * sx_;
  const double y0 = box.y * sy_, h = box.h * sy_;
  p.bandTop = row(y0 + kBandTop * h);
  p.bandEnd = row(y0 + kBandBottom * h) + 1;
  return p;
}

std::optional<double> LaserCells::coreDepth(const Box& box, int minCells) const {
  if (empty()) return std::nullopt;
  const Place p = place(box);
  std::vector<float> core;
  for (int r = p.bandTop; r < p.bandEnd; ++r)
    for (int c = col(p.x0 + 0.25 * p.width()); c <= col(p.x1 - 0.25 * p.width()); ++c)
      if (valid(r, c)) core.push_back(d_(r, c));
  if (static_cast<int>(core.size()) < std::max(1, minCells)) return std::nullopt;
  std::nth_element(core.begin(), core.begin() + static_cast<std::ptrdiff_t>(core.size() / 2), core.end());
  return core[core.size() / 2];
}

}  // namespace fusedet::boosting
