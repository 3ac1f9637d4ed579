// SPDX-License-Identifier: Apache-2.0
#include "jackknife.h"

#include <cmath>
#include <stdexcept>

#include "fusedet/fusion/calibration/calib_targetless.h"

namespace fusedet::fusion::detail {

PoseSpread jackknifeSpread(const std::vector<Eigen::Isometry3d>& leaveOneOut, const Eigen::Isometry3d& full) {
  const std::size_t n = leaveOneOut.size();
  if (n < 2) throw std::invalid_argument("jackknife needs at least 2 leave-one-out solutions");
  std::vector<Eigen::Matrix<double, 6, 1>> deltas;
  for (const Eigen::Isometry3d& T : leaveOneOut) deltas.push_back(poseDifference(T, full));
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero(), var = Eigen::Matrix<double, 6, 1>::Zero();
  for (const auto& d : deltas) mean += d / static_cast<double>(n);
  for (const auto& d : deltas) var += (d - mean).cwiseAbs2();
  var *= static_cast<double>(n - 1) / static_cast<double>(n);
  return {var.head<3>().cwiseSqrt(), var.tail<3>().cwiseSqrt()};
}

}  // namespace fusedet::fusion::detail
