// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/laser_extent.h"

#include <algorithm>
#include <cmath>
#include <optional>
#include <vector>

#include "fusedet/boost/laser_cells.h"

namespace fusedet::boosting {

namespace {

// One column of the band: the share of its valid cells within `tol` of `ref` (-1: none valid) and
// their median (the next column's reference).
struct ColumnFit {
  double share = -1, median = 0;
};
ColumnFit fitColumn(const LaserCells& cells, int r0, int r1, int c, double ref, double tol) {
  std::vector<float> on;
  int valid = 0;
  for (int r = r0; r < r1; ++r)
    if (cells.valid(r, c)) {
      ++valid;
      if (std::abs(cells.distance(r, c) - ref) <= tol) on.push_back(cells.distance(r, c));
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
std::optional<int> walk(const LaserCells& cells, int r0, int r1, int from, int dir, int limit, double d0,
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

}  // namespace

Box laserExtentBox(const Box& box, const LayerStack& stack, const LaserExtentParams& p) {
  if (!p.enabled || !(box.w > 0) || !(box.h > 0)) return box;
  const LaserCells cells(stack);
  if (cells.empty()) return box;
  const LaserCells::Place at = cells.place(box);
  const std::optional<double> ref = cells.coreDepth(at, p.minCells);
  if (!ref) return box;  // too few laser cells on the box
  const double d0 = *ref;
  const int r0 = at.bandTop, r1 = at.bandEnd;
  const double x0 = at.x0, x1 = at.x1, w = at.width();
  const int centre = cells.col((x0 + x1) / 2);
  if (const ColumnFit f = fitColumn(cells, r0, r1, centre, d0, p.tolerance); f.share >= 0 && f.share < p.minShare)
    return box;  // the core's median is not its middle's distance
  const double reach = p.maxMove * w;
  double left = x0, right = x1;
  if (const auto l = walk(cells, r0, r1, centre, -1, cells.col(x0 - reach), d0, p))
    left = std::min(x0, std::max(x0 - reach, *l - p.margin * w));
  if (const auto r = walk(cells, r0, r1, centre, +1, cells.col(x1 + reach), d0, p))
    right = std::max(x1, std::min(x1 + reach, *r + 1 + p.margin * w));
  Box out = box;
  out.x = cells.toReferenceX(left);
  out.w = cells.toReferenceX(right - left);
  return out;
}

void refineToLaserExtent(std::vector<Detection>& detections, const LayerStack& stack, const LaserExtentParams& params) {
  if (!params.enabled) return;
  for (Detection& d : detections) {
    d.box = laserExtentBox(d.box, stack, params);
    d.unitBox = stack.toUnit(d.box);
  }
}

}  // namespace fusedet::boosting
