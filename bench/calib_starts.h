// SPDX-License-Identifier: Apache-2.0
#pragma once
// Perturbed starts for the calibration benchmarks (calib_kitti_bench, calib_heldout_bench).

#include <Eigen/Geometry>
#include <cmath>
#include <random>

namespace fusedet::bench {

// A rotation of angle in [fraction, 1] * maxDeg about a uniformly random axis, and a translation
// of length in [fraction, 1] * maxT in a uniformly random direction, applied in the camera frame.
inline Eigen::Isometry3d perturbedStart(const Eigen::Isometry3d& truth, double maxDeg, double maxT, double fraction,
                                        std::mt19937& rng) {
  std::normal_distribution<double> gauss;
  std::uniform_real_distribution<double> mag(fraction, 1.0);
  const Eigen::Vector3d axis = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  const Eigen::Vector3d dir = Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = Eigen::AngleAxisd(mag(rng) * maxDeg * M_PI / 180.0, axis).toRotationMatrix();
  d.translation() = mag(rng) * maxT * dir;
  return d * truth;
}

}  // namespace fusedet::bench
