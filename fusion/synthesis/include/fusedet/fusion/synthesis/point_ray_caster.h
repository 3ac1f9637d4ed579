// SPDX-License-Identifier: Apache-2.0
#pragma once
// PointRayCaster: casts rays into a measured point cloud (a Velodyne sweep) - what a laser beam
// through that scene would have returned. Points are binned by direction as seen from the cloud's
// origin; a ray (origin near that origin, unit direction) returns the nearest point along it among
// those within `toleranceRad` of the ray (angular distance seen from the ray's origin), i.e. the
// first surface the beam meets; its range is the distance along the ray.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <vector>

#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

struct RayHit {
  double range = 0;      // [m] along the ray, from its origin
  float remission = 0;   // of the point hit
  std::uint32_t index = 0;  // into the cloud
};

class PointRayCaster {
 public:
  // maxOriginOffset: how far ray origins may lie from (0,0,0) [m]; minRange: points nearer than
  // this to (0,0,0) are ignored (they would need a wide search and are the sensor's own vehicle).
  PointRayCaster(const Sweep& cloud, double toleranceRad, double maxOriginOffset = 0.1, double minRange = 2.0);

  std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const;
  double toleranceRad() const { return tolerance_; }

 private:
  int cellOf(double azimuth, double elevation) const;

  std::vector<Eigen::Vector3f> points_;
  std::vector<float> remission_;
  std::vector<std::uint32_t> order_;   // point indices sorted by cell
  std::vector<std::uint32_t> start_;   // cell -> first position in order_ (CSR), size cells + 1
  double tolerance_, maxOffset_, minRange_;
  double bin_;
  int azBins_, elBins_;
  int window_;  // cells searched on each side of the ray's cell
};

}  // namespace fusedet::fusion
