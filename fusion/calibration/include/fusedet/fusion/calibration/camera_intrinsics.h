// SPDX-License-Identifier: Apache-2.0
#pragma once
// Camera intrinsics from views of a chessboard (`fusedet calibrate-camera`): the pinhole K and
// OpenCV's five-coefficient distortion (k1 k2 p1 p2 k3, ROS "plumb_bob"), with the board's pose in
// every view. Zhang's closed form (a homography per view, zero skew) starts a Levenberg-Marquardt
// search over all parameters that minimises the squared reprojection error in pixels.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <opencv2/core.hpp>
#include <vector>

#include "fusedet/fusion/calibration/board_corners.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {

struct IntrinsicsResult {
  CameraModel camera;                         // K, distortion {k1, k2, p1, p2, k3}, the image size
  std::vector<Eigen::Isometry3d> boardToCamera;  // per view: board points (metres) -> camera
  double rmsPx = 0;                           // over every corner of every view
  std::vector<double> viewRmsPx;              // per view
  // 1-sigma of fx fy cx cy k1 k2 p1 p2 k3 from the Gauss-Newton covariance at the minimum, with
  // the residual variance estimated from the fit (corner noise assumed equal and independent).
  Eigen::Matrix<double, 9, 1> sigma = Eigen::Matrix<double, 9, 1>::Zero();
  int iterations = 0;
};

// views[i] = the corners of view i in boardPoints(board) order. Needs 3 or more views (Zhang's
// closed form needs the board at 3 or more orientations: fewer, or views that are all parallel,
// throw std::invalid_argument saying so).
IntrinsicsResult calibrateIntrinsics(const std::vector<std::vector<cv::Point2f>>& views, const BoardSpec& board,
                                     cv::Size imageSize);

// A camera point through K and the five-coefficient distortion to pixels (OpenCV's model).
Eigen::Vector2d projectPoint(const CameraModel& camera, const Eigen::Vector3d& pointInCamera);

}  // namespace fusedet::fusion
