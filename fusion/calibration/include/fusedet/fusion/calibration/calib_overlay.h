// SPDX-License-Identifier: Apache-2.0
#pragma once
// Pictures that let a person judge an extrinsic calibration: laser points drawn on the camera
// image, coloured by distance (near red, far blue), so misalignment shows at object outlines.

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <string>

#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

// The image (8-bit grey or BGR; drawn as dimmed grey) with the points of `sweep` that land in it
// under laserToCamera and K, each a small dot coloured by its distance, up to maxRange [m].
cv::Mat drawLaserOverlay(const cv::Mat& image, const Sweep& sweep, const Eigen::Matrix3d& K,
                         const Eigen::Isometry3d& laserToCamera, double maxRange = 40.0);

// Two overlays stacked vertically with a caption on each ("before", "after").
cv::Mat stackOverlays(const cv::Mat& top, const std::string& topCaption, const cv::Mat& bottom,
                      const std::string& bottomCaption);

}  // namespace fusedet::fusion
