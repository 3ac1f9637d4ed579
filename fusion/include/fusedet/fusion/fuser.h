// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fuser: one camera image + one sweep -> a LayerStack with the camera layers (red, green, blue,
// intensity, hue) at image resolution and the laser layers (distance, remission, with a validity
// mask) at their own lower resolution, registered through the undistorted image plane.
// The same code serves live data (distorted camera, extrinsics from config) and KITTI (rectified
// camera, calib files).

#include <opencv2/core/mat.hpp>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/projection.h"
#include "fusedet/fusion/sweep.h"
#include "fusedet/fusion/undistorter.h"

namespace fusedet::fusion {

// Wall time of each step of one fuse() call, in milliseconds.
struct FuseTimings {
  double undistortMs = 0, cameraLayersMs = 0, projectMs = 0, rasteriseMs = 0, totalMs = 0;
};

class Fuser {
 public:
  // sweepToCamera maps sweep points (Sweep::frame) to the camera frame (x right, y down, z ahead).
  Fuser(const CameraModel& camera, const Eigen::Isometry3d& sweepToCamera, ProjectionConfig config = {});

  // bgr: the camera image as captured (distorted, the model's size), CV_8UC3. The stack's stamp
  // and source are left to the caller.
  LayerStack fuse(const cv::Mat& bgr, const Sweep& sweep, FuseTimings* timings = nullptr) const;

  // The layers fuse() makes, in its order (a model needing any other cannot run on its stacks;
  // hue_distance is derived from hue per model at detection time).
  static std::vector<std::string> layerNames();

  const PinholeProjection& projection() const { return projection_; }
  const ProjectionConfig& config() const { return config_; }
  const Undistorter& undistorter() const { return undistorter_; }

 private:
  PinholeProjection projection_;
  ProjectionConfig config_;
  Undistorter undistorter_;
};

}  // namespace fusedet::fusion
