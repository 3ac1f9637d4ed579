// SPDX-License-Identifier: Apache-2.0
#pragma once
// Leave-one-out (jackknife) spread of a pose estimate, used as the calibrations' uncertainty.

#include <Eigen/Geometry>
#include <vector>

namespace fusedet::fusion::detail {

struct PoseSpread {
  Eigen::Vector3d rotationStdDeg;  // about the camera axes
  Eigen::Vector3d translationStd;  // [m]
};

// The solutions with one input left out each, relative to the full solution `full` (as rotation
// vector and translation in the camera frame); variance = (n - 1) / n * sum of squared deviations
// from their mean (Efron & Stein). Needs >= 2 solutions.
PoseSpread jackknifeSpread(const std::vector<Eigen::Isometry3d>& leaveOneOut, const Eigen::Isometry3d& full);

}  // namespace fusedet::fusion::detail
