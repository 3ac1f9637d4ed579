// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/localize.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "fusedet/fusion/projection.h"

namespace fusedet::daemon {

std::optional<Position> localize(const LayerStack& stack, const Box& box, const Eigen::Matrix3d& K,
                                 const Eigen::Isometry3d& sweepToCamera, const LocalizeParams& params) {
  const Layer* dist = stack.find(layer::kDistance);
  if (!dist || dist->data.type() != CV_32F || stack.width() <= 0 || stack.height() <= 0) return std::nullopt;
  const double margin = (1.0 - params.coreShare) / 2;
  const Box core{box.x + margin * box.w, box.y + margin * box.h, box.w * params.coreShare, box.h * params.coreShare};
  const Box cells = LayerStack::toLayerPixels(*dist, stack.toUnit(core));
  const int x0 = std::max(0, static_cast<int>(std::floor(cells.x)));
  const int y0 = std::max(0, static_cast<int>(std::floor(cells.y)));
  const int x1 = std::min(dist->width(), static_cast<int>(std::ceil(cells.right())));
  const int y1 = std::min(dist->height(), static_cast<int>(std::ceil(cells.bottom())));
  std::vector<float> ranges;
  for (int y = y0; y < y1; ++y) {
    const float* d = dist->data.ptr<float>(y);
    const std::uint8_t* m = dist->hasMask() ? dist->valid.ptr<std::uint8_t>(y) : nullptr;
    for (int x = x0; x < x1; ++x) {
      // Filled holes are interpolated, often across the object's edge: only measured cells count.
      if (m && m[x] != fusion::kMaskMeasured) continue;
      if (d[x] > 0 && std::isfinite(d[x])) ranges.push_back(d[x]);
    }
  }
  if (static_cast<int>(ranges.size()) < std::max(1, params.minCells)) return std::nullopt;
  const auto k = static_cast<std::size_t>(params.percentile * static_cast<double>(ranges.size() - 1));
  std::nth_element(ranges.begin(), ranges.begin() + static_cast<std::ptrdiff_t>(k), ranges.end());
  Position p;
  p.range = ranges[k];
  p.cells = static_cast<int>(ranges.size());
  const Eigen::Vector3d ray = K.inverse() * Eigen::Vector3d(box.centerX(), box.centerY(), 1.0);
  p.camera = ray.normalized() * p.range;
  p.robot = sweepToCamera.inverse() * p.camera;
  return p;
}

}  // namespace fusedet::daemon
