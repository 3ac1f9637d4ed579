// SPDX-License-Identifier: Apache-2.0
#pragma once
// Localize: the 3D position of a detection from the distance layer inside its box. Background
// cells (behind the object) and filled holes would pull a mean away, so the range is a low
// percentile of the MEASURED cells in the central half of the box: the object is the nearest
// large surface there. The point lies on the ray through the box centre in the undistorted image.

#include <Eigen/Geometry>
#include <optional>

#include "fusedet/core/box.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::daemon {

struct LocalizeParams {
  double percentile = 0.25;  // of the measured ranges in the core of the box
  double coreShare = 0.5;    // width and height share of the box, centred, that is looked at
  int minCells = 3;          // fewer measured cells: no position
};

struct Position {
  Eigen::Vector3d camera;  // camera frame: x right, y down, z ahead [m]
  Eigen::Vector3d robot;   // the sweep's frame (the robot / laser base frame in live mode) [m]
  double range = 0;        // [m] from the camera centre
  int cells = 0;           // measured cells the range came from
};

// K: the pinhole of the stack's (undistorted) reference image; sweepToCamera: the fuser's
// extrinsics. Nothing when the stack has no distance layer or too few measured cells.
std::optional<Position> localize(const LayerStack& stack, const Box& box, const Eigen::Matrix3d& K,
                                 const Eigen::Isometry3d& sweepToCamera, const LocalizeParams& params = {});

}  // namespace fusedet::daemon
