#include "fusedet/boost/laser_extent.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <opencv2/core.hpp>
#include <optional>

namespace fusedet::boosting {

namespace {

constexpr double kBandTop = 0.35, kBandBottom = 0.85;  // rows of the band, fractions of the box's height

struct Cells {
  cv::Mat1f d;
  cv::Mat mask;  // empty = every cell measured
  bool valid(int r, int c) const {
    const float v = d(r, c);
    return v > 0 && std::isfinite(v) && (mask.empty() || mask.at<std::uint8_t>(r, c) != 0);
  }
};

// One column of the band: the share of its valid cells within `tol` of `ref` (-1: none valid) and
// their median (the next column's reference).
struct ColumnFit {
  double share = -1, median = 0;
};
ColumnFit fitColumn(const Cells& cells, int r0, int r1, int c, double ref, double tol) {
  std::vector<float> on;
  int valid = 0;
  for (int r = r0; r < r1; ++r)
    if (cells.valid(r, c)) {
      ++valid;
      if (std::abs(cells.d(r, c) - ref) <= tol) on.push_back(cells.d(r, c));
    }
  ColumnFit f;
  if (valid == 0) return f;
  f.share = double(on.size()) / valid;
  if (!on.empty()) {
    std::nth_element(on.begin(), on.begin() + static_cast<std::ptrdiff_t>(on.size() / 2), on.end());
    f.median = on[on.size() / 2];
  }
  return f;
}

// Last object column walking from `from` by `dir` (+1 / -1) up to `limit` (inclusive); nothing
// when the walk reaches the limit.
std::optional<int> walk(const Cells& cells, int r0, int r1, int from, int dir, int limit, double d0,
                        const LaserExtentParams& p) {
  int last = from;
  double ref = d0;
  for (int c = from; dir > 0 ? c <= limit : c >= limit; c += dir) {
    const ColumnFit f = fitColumn(cells, r0, r1, c, ref, p.tolerance);
    if (f.share < 0) continue;
    if (f.share < p.minShare) return last;
    last = c;
    ref = f.median;
  }
  return std::nullopt;
}

// The stack's distance cells and the scale from reference pixels to them; nothing when the stack
// has no distance layer.
struct Grid {
  Cells cells;
  double sx = 1, sy = 1;
  int col(double v) const { return std::clamp(static_cast<int>(std::floor(v)), 0, cells.d.cols - 1); }
  int row(double v) const { return std::clamp(static_cast<int>(std::floor(v)), 0, cells.d.rows - 1); }
};
std::optional<Grid> gridOf(const LayerStack& stack) {
  if (stack.width() <= 0 || stack.height() <= 0) return std::nullopt;
  const Layer* layer = stack.find(layer::kDistance);
  if (!layer || layer->data.empty()) return std::nullopt;
  Grid g;
  if (layer->data.type() == CV_32F)
    g.cells.d = layer->data;  // shares the layer's cells
  else
    layer->data.convertTo(g.cells.d, CV_32F);
  g.cells.mask = layer->valid;
  g.sx = double(g.cells.d.cols) / stack.width();
  g.sy = double(g.cells.d.rows) / stack.height();
  return g;
}

// Median distance of the valid cells in rows [r0, r1) and columns [c0, c1]; nothing with fewer
// than minCells of them.
std::optional<double> referenceDistance(const Cells& cells, int r0, int r1, int c0, int c1, int minCells) {
  std::vector<float> core;
  for (int r = r0; r < r1; ++r)
    for (int c = c0; c <= c1; ++c)
      if (cells.valid(r, c)) core.push_back(cells.d(r, c));
  if (static_cast<int>(core.size()) < std::max(1, minCells)) return std::nullopt;
  std::nth_element(core.begin(), core.begin() + static_cast<std::ptrdiff_t>(core.size() / 2), core.end());
  return core[core.size() / 2];
}

}  // namespace

Box laserExtentBox(const Box& box, const LayerStack& stack, const LaserExtentParams& p) {
  if (!p.enabled || !(box.w > 0) || !(box.h > 0)) return box;
  const std::optional<Grid> grid = gridOf(stack);
  if (!grid) return box;
  const Cells& cells = grid->cells;
  const double sx = grid->sx, sy = grid->sy;
  const double x0 = box.x * sx, x1 = box.right() * sx, y0 = box.y * sy, h = box.h * sy, w = x1 - x0;
  const auto col = [&](double v) { return grid->col(v); };
  const auto row = [&](double v) { return grid->row(v); };
  const int r0 = row(y0 + kBandTop * h), r1 = row(y0 + kBandBottom * h) + 1;
  const std::optional<double> ref =
      referenceDistance(cells, r0, r1, col(x0 + 0.25 * w), col(x1 - 0.25 * w), p.minCells);
  if (!ref) return box;
  const double d0 = *ref;
  const int centre = col((x0 + x1) / 2);
  if (const ColumnFit f = fitColumn(cells, r0, r1, centre, d0, p.tolerance); f.share >= 0 && f.share < p.minShare)
    return box;  // the core's median is not its middle's distance
  const double reach = p.maxMove * w;
  double left = x0, right = x1;
  if (const auto l = walk(cells, r0, r1, centre, -1, col(x0 - reach), d0, p))
    left = std::min(x0, std::max(x0 - reach, *l - p.margin * w));
  if (const auto r = walk(cells, r0, r1, centre, +1, col(x1 + reach), d0, p))
    right = std::max(x1, std::min(x1 + reach, *r + 1 + p.margin * w));
  Box out = box;
  out.x = left / sx;
  out.w = (right - left) / sx;
  return out;
}

std::optional<LaserRows> laserRows(const Box& box, const LayerStack& stack, const LaserExtentParams& p) {
  if (!(box.w > 0) || !(box.h > 0)) return std::nullopt;
  const std::optional<Grid> grid = gridOf(stack);
  if (!grid) return std::nullopt;
  const Cells& cells = grid->cells;
  const double x0 = box.x * grid->sx, x1 = box.right() * grid->sx, y0 = box.y * grid->sy, h = box.h * grid->sy;
  const double w = x1 - x0;
  const int c0 = grid->col(x0 + 0.25 * w), c1 = grid->col(x1 - 0.25 * w);
  const std::optional<double> d0 =
      referenceDistance(cells, grid->row(y0 + kBandTop * h), grid->row(y0 + kBandBottom * h) + 1, c0, c1, p.minCells);
  if (!d0) return std::nullopt;
  std::optional<int> top, bottom;
  for (int r = grid->row(y0 - p.maxMove * h); r <= grid->row(y0 + h + p.maxMove * h); ++r) {
    int valid = 0, on = 0;
    for (int c = c0; c <= c1; ++c)
      if (cells.valid(r, c)) {
        ++valid;
        on += std::abs(cells.d(r, c) - *d0) <= p.tolerance ? 1 : 0;
      }
    if (valid == 0 || on < p.minShare * valid) continue;
    if (!top) top = r;
    bottom = r;
  }
  if (!top) return std::nullopt;
  return LaserRows{*top / grid->sy, (*bottom + 1) / grid->sy};
}

void refineToLaserExtent(std::vector<Detection>& detections, const LayerStack& stack, const LaserExtentParams& params) {
  if (!params.enabled) return;
  for (Detection& d : detections) {
    d.box = laserExtentBox(d.box, stack, params);
    d.unitBox = stack.toUnit(d.box);
  }
}

}  // namespace fusedet::boosting
