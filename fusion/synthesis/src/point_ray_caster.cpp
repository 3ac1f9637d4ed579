// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/synthesis/point_ray_caster.h"

#include <algorithm>
#include <cmath>

namespace fusedet::fusion {

PointRayCaster::PointRayCaster(const Sweep& cloud, double toleranceRad, double maxOriginOffset, double minRange)
    : tolerance_(toleranceRad), maxOffset_(maxOriginOffset), minRange_(minRange) {
  // Bins of the tolerance's size: the search window covers the tolerance plus the parallax a ray
  // origin up to maxOffset away causes at minRange.
  bin_ = std::max(toleranceRad, 1e-3);
  azBins_ = static_cast<int>(std::ceil(2 * M_PI / bin_));
  elBins_ = static_cast<int>(std::ceil(M_PI / bin_)) + 1;
  window_ = static_cast<int>(std::ceil((toleranceRad + std::asin(std::min(1.0, maxOffset_ / minRange_))) / bin_));
  std::vector<int> cells;
  for (std::uint32_t i = 0; i < cloud.points.size(); ++i) {
    const SweepPoint& p = cloud.points[i];
    const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
    if (!(r >= minRange_) || !std::isfinite(r)) continue;
    points_.emplace_back(p.x, p.y, p.z);
    remission_.push_back(p.remission);
    cells.push_back(cellOf(std::atan2(p.y, p.x), std::asin(std::clamp(p.z / r, -1.0, 1.0))));
  }
  const std::size_t nCells = static_cast<std::size_t>(azBins_) * static_cast<std::size_t>(elBins_);
  start_.assign(nCells + 1, 0);
  for (int c : cells) ++start_[static_cast<std::size_t>(c) + 1];
  for (std::size_t c = 0; c < nCells; ++c) start_[c + 1] += start_[c];
  order_.resize(points_.size());
  std::vector<std::uint32_t> fill(start_.begin(), start_.end() - 1);
  for (std::uint32_t i = 0; i < cells.size(); ++i) order_[fill[static_cast<std::size_t>(cells[i])]++] = i;
}

int PointRayCaster::cellOf(double azimuth, double elevation) const {
  int a = static_cast<int>(std::floor((azimuth + M_PI) / bin_));
  a = ((a % azBins_) + azBins_) % azBins_;
  const int e = std::clamp(static_cast<int>(std::floor((elevation + M_PI / 2) / bin_)), 0, elBins_ - 1);
  return e * azBins_ + a;
}

std::optional<RayHit> PointRayCaster::cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const {
  const double az = std::atan2(direction.y(), direction.x());
  const double el = std::asin(std::clamp(direction.z(), -1.0, 1.0));
  const int a0 = static_cast<int>(std::floor((az + M_PI) / bin_));
  const int e0 = static_cast<int>(std::floor((el + M_PI / 2) / bin_));
  // Near the poles one azimuth bin is narrow: widen the azimuth window by 1/cos(elevation).
  const double cosEl = std::max(std::cos(el) - window_ * bin_, 0.05);
  const int aw = std::min(azBins_ / 2, static_cast<int>(std::ceil(window_ / cosEl)));
  const double tan2 = std::tan(tolerance_) * std::tan(tolerance_);
  std::optional<RayHit> best;
  for (int e = std::max(0, e0 - window_); e <= std::min(elBins_ - 1, e0 + window_); ++e) {
    for (int da = -aw; da <= aw; ++da) {
      const int a = (((a0 + da) % azBins_) + azBins_) % azBins_;
      const std::size_t cell = static_cast<std::size_t>(e) * static_cast<std::size_t>(azBins_) + static_cast<std::size_t>(a);
      for (std::uint32_t k = start_[cell]; k < start_[cell + 1]; ++k) {
        const std::uint32_t i = order_[k];
        const Eigen::Vector3d v = points_[i].cast<double>() - origin;
        const double along = v.dot(direction);
        if (along <= 0 || (best && along >= best->range)) continue;
        const double perp2 = (v - along * direction).squaredNorm();
        if (perp2 > tan2 * along * along) continue;
        best = RayHit{along, remission_[i], i};
      }
    }
  }
  return best;
}

}  // namespace fusedet::fusion
