// SPDX-License-Identifier: Apache-2.0
#pragma once
// A sensor log as calibration input: the log is replayed through the live decoders with the rig
// it carries (metadata "fusedet.config"), sweeps are assembled and paired with camera frames as
// in fusedetd, and a few pairs spread over the whole log become targetless calibration frames
// (undistorted image + sweep in the laser base frame).

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <vector>

#include "fusedet/fusion/calibration/calib_targetless.h"

namespace fusedet::sensor_logs {

struct LogCalibrationInput {
  std::vector<fusion::CalibFrame> frames;  // name "sweep-<id>"; images undistorted with the log's camera model
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();  // pinhole of the undistorted images
  Eigen::Isometry3d laserToCamera = Eigen::Isometry3d::Identity();  // the log's fusion.laser_to_camera
  std::size_t sweeps = 0;   // sweeps assembled from the log
  std::size_t paired = 0;   // of them, paired with a camera frame
};

// Throws std::runtime_error when the log has no rig metadata or no sweep pairs with a frame,
// mcap::McapError when it is no readable log, daemon::ConfigError when its config is bad.
// Memory stays bounded by about 2 x maxFrames pairs, whatever the log's length.
LogCalibrationInput loadLogCalibrationInput(const std::filesystem::path& log, std::size_t maxFrames);

}  // namespace fusedet::sensor_logs
