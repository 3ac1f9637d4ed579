#pragma once
// Target-based laser->camera calibration with a checkerboard seen by both sensors in >= 3 poses
// (Zhang & Pless, "Extrinsic calibration of a camera and laser range finder", IROS 2004, with the
// board plane measured directly by a 3D laser): each pose gives the board plane in the camera
// (corner detection + solvePnP) and the board's points in the laser frame (RANSAC plane fit);
// the transform puts every laser board point on its camera board plane.
// Closed-form start (rotation from the plane normals, translation from the plane distances),
// then Gauss-Newton on the point-to-plane distances.

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/types.hpp>
#include <limits>
#include <stdexcept>
#include <vector>

#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {

// Input that cannot give a calibration (board not found, too few points, degenerate poses).
class CalibrationError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// {p : normal . p = distance}, |normal| = 1, oriented so that distance >= 0 (the sensor's origin
// on the negative side): a board seen by both sensors then has matching normals.
struct Plane {
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
  double distance = 0;
};

struct Checkerboard {
  cv::Size innerCorners{7, 5};  // corners per row, per column (OpenCV's patternSize)
  double squareSize = 0.1;      // [m]
};

// Corners with sub-pixel refinement, OpenCV's order. Throws CalibrationError if not found.
std::vector<cv::Point2f> detectCheckerboard(const cv::Mat& image, const Checkerboard& board);
// The board plane in the camera frame from its corners (solvePnP with the camera's distortion).
Plane cameraBoardPlane(const std::vector<cv::Point2f>& corners, const Checkerboard& board, const CameraModel& camera);

struct LaserPlaneOptions {
  double inlierDistance = 0.03;  // [m]
  int iterations = 300;
  std::size_t minInliers = 30;
  unsigned seed = 1;             // RANSAC sampling is deterministic
};

struct LaserPlane {
  Plane plane;                          // least-squares fit to the inliers
  std::vector<Eigen::Vector3d> inliers;
  double rms = 0;                       // [m] inlier distance to the plane
};

// The dominant plane of laser points around the board (crop the scene to the board's
// surroundings first). Throws CalibrationError with fewer than minInliers points or inliers.
LaserPlane fitLaserBoardPlane(const std::vector<Eigen::Vector3d>& points, const LaserPlaneOptions& options = {});

struct BoardObservation {
  Plane camera;                             // board plane, camera frame
  std::vector<Eigen::Vector3d> laserPoints; // board points, laser frame (e.g. LaserPlane::inliers)
};

struct TargetCalibrationOptions {
  std::size_t minPointsPerBoard = 30;
  // Board normals must spread: the smallest singular value of the stacked unit normals, divided
  // by sqrt(poses), must reach this (0 = all parallel or all in one pencil; ~0.1 = about 10 deg of tilt).
  double minNormalSpread = 0.1;
  int iterations = 30;
};

struct TargetCalibration {
  Eigen::Isometry3d laserToCamera = Eigen::Isometry3d::Identity();
  double rmsDistance = 0;  // [m] laser board points to their camera planes
  // 1-sigma leave-one-board-out jackknife (>= 4 poses), about the camera axes; NaN otherwise.
  Eigen::Vector3d rotationStdDeg = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
  Eigen::Vector3d translationStd = Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN());
};

// Throws CalibrationError naming the problem: fewer than 3 poses, a pose with too few laser
// points, or board normals that leave a direction unconstrained (parallel boards, or all boards
// tilted about one axis only).
TargetCalibration calibrateFromBoards(const std::vector<BoardObservation>& boards,
                                      const TargetCalibrationOptions& options = {});

}  // namespace fusedet::fusion
