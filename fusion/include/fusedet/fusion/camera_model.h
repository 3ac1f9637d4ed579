// SPDX-License-Identifier: Apache-2.0
#pragma once
// Camera model: pinhole K plus OpenCV distortion coefficients (design §4), read from a ROS
// camera_info YAML or an OpenCV calibration YAML, and the laser->camera extrinsics from config.

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace fusedet::fusion {

struct CameraModel {
  int width = 0, height = 0;
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  // OpenCV order: k1 k2 p1 p2 [k3 [k4 k5 k6 [s1 s2 s3 s4 [tx ty]]]]; empty = none.
  std::vector<double> distortion;

  bool hasDistortion() const;
};

// Reads either format, told apart by its keys:
//  - ROS camera_info (camera_calibration_parsers): image_width, image_height,
//    camera_matrix {rows, cols, data}, distortion_model (plumb_bob | rational_polynomial),
//    distortion_coefficients {rows, cols, data};
//  - OpenCV (cv::FileStorage, "%YAML:1.0"): image_width, image_height, camera_matrix and
//    distortion_coefficients as !!opencv-matrix.
// Throws std::runtime_error naming the file and the problem (missing key, wrong matrix shape,
// non-positive focal length or size, unknown distortion model, unparsable YAML).
CameraModel readCameraModel(const std::filesystem::path& file);
CameraModel parseCameraModel(const std::string& yamlText, const std::string& what = "camera YAML");

// The ROS camera_info YAML parseCameraModel reads back (distortion_model plumb_bob for 4 or 5
// coefficients, else rational_polynomial; rectification identity, projection [K | 0]), with
// `comment` as leading '#' lines. Doubles at 17 significant digits: the text round-trips exactly.
std::string formatCameraModel(const CameraModel& camera, const std::string& cameraName, const std::string& comment);

// A rigid transform from roll/pitch/yaw in degrees applied as Rz(yaw) * Ry(pitch) * Rx(roll),
// then the translation: p' = R p + t (the `fusion.laser_to_camera` config convention).
Eigen::Isometry3d rigidFromRpyDeg(const std::array<double, 3>& rpyDeg, const std::array<double, 3>& translation);
// The inverse: roll, pitch, yaw in degrees with pitch in [-90, 90], roll and yaw in (-180, 180].
// At pitch +-90 (gimbal lock) only roll -+ yaw is defined; roll is then reported as 0.
std::array<double, 3> rpyDegFromRotation(const Eigen::Matrix3d& R);

}  // namespace fusedet::fusion
