// SPDX-License-Identifier: Apache-2.0
#pragma once
// A stack's `distance` layer read in boxes given in the stack's reference pixels: the one place
// that says which laser cells a box covers and what distance the box is at, e.g. for the
// laser-extent refinement (laser_extent.h: reference distance, column walk).
//
// A cell is valid when the layer's mask (if any) is non-zero there and its distance is finite and
// > 0. A box maps onto the cells through unit coordinates (the layer has its own resolution). Its
// band is the rows from 35 % to 85 % of its height (a car's body below the windows, which the
// laser passes through; above the road under it); its core is the band's middle half of columns.
// The box's distance (coreDepth) is the median of the core's valid cells.

#include <cmath>
#include <optional>

#include <opencv2/core/mat.hpp>

#include "fusedet/core/box.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

class LaserCells {
 public:
  // empty() when the stack has no (or an empty) distance layer or no reference size.
  explicit LaserCells(const LayerStack& stack);

  bool empty() const { return d_.empty(); }
  int cols() const { return d_.cols; }
  int rows() const { return d_.rows; }
  bool valid(int r, int c) const {
    const float v = d_(r, c);
    return v > 0 && std::isfinite(v) && (mask_.empty() || mask_.at<unsigned char>(r, c) != 0);
  }
  float distance(int r, int c) const { return d_(r, c); }

  // A box in cell coordinates: x0 / x1 (left / right edge), y0 (top) and h (height), fractional;
  // band rows [bandTop, bandEnd), core columns [coreFirst, coreLast].
  struct Place {
    double x0 = 0, x1 = 0, y0 = 0, h = 0;
    int bandTop = 0, bandEnd = 0;
    int coreFirst = 0, coreLast = 0;
    double width() const { return x1 - x0; }
  };
  Place place(const Box& box) const;  // only on a non-empty layer
  int col(double x) const;  // the cell column containing x, clamped to the layer
  int row(double y) const;  // the cell row containing y, clamped to the layer
  double toReferenceX(double x) const { return x / sx_; }
  double toReferenceY(double y) const { return y / sy_; }

  // Median distance of the valid cells of the box's core; nullopt with fewer than
  // max(1, minCells) of them (no laser on the box) or an empty layer.
  std::optional<double> coreDepth(const Place& at, int minCells) const;

 private:
  cv::Mat1f d_;
  cv::Mat mask_;  // empty = every cell measured
  double sx_ = 1, sy_ = 1;  // cells per reference pixel
};

}  // namespace fusedet::boosting
