// SPDX-License-Identifier: Apache-2.0
#pragma once
// Score profiles of targetless calibration: the agreement measures along each of the 6 axes
// around a transform. The diagnosis before trusting an optimiser: at the right transform every
// measure should peak at offset 0; a flat profile shows a direction the frames do not observe.

#include <string>
#include <vector>

#include "fusedet/fusion/calibration/calib_targetless.h"

namespace fusedet::fusion {

// Rotations about and translations along the camera's x, y, z around `reference`, offsets
// k = -steps..steps: k x rotationStepDeg or k x translationStep (points chosen under reference).
struct ScoreProfile {
  int steps = 0;
  double rotationStepDeg = 0, translationStep = 0;  // [deg], [m]
  std::vector<AlignmentScore> scores[6];            // per axis: rot_x rot_y rot_z t_x t_y t_z; 2 x steps + 1 each
  double offset(int axis, int k) const { return k * (axis < 3 ? rotationStepDeg : translationStep); }
  // Offset [deg or m] at which the edge measure (or mutual information) is largest along the axis.
  double peakOffset(int axis, bool mutualInformation) const;
};
ScoreProfile scoreProfile(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K, const Eigen::Isometry3d& reference,
                          int steps = 20, double rotationStepDeg = 0.05, double translationStep = 0.005,
                          const TargetlessOptions& options = {});

// One table per measure (edges, mi): a row per offset, a column per axis, then each axis' peak.
std::string formatScoreProfile(const ScoreProfile& profile);

}  // namespace fusedet::fusion
