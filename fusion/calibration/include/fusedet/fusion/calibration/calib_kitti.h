// SPDX-License-Identifier: Apache-2.0
#pragma once
// KITTI frames as calibration input: one rig (the frames whose calib files agree), a few frames
// spread over the drives given, the rig's pinhole and its laser->camera transform.

#include <Eigen/Geometry>
#include <filesystem>
#include <string>
#include <vector>

#include "fusedet/fusion/calibration/calib_targetless.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::fusion {

struct KittiCalibrationInput {
  std::vector<CalibFrame> frames;    // name "<dir name>/<id>"
  KittiCalib calib;                  // the rig's calib file
  Eigen::Matrix3d K;                 // P2's pinhole: the rectified colour camera
  // Velodyne -> rectified colour camera (kittiProjection's sweepToCamera): what the calib says.
  Eigen::Isometry3d laserToCamera;
  std::size_t rigFrames = 0;         // frames of the chosen rig found in the directories
  std::size_t otherRigFrames = 0;    // frames skipped because their calib differs (another day)
};

// Reads the calib of every frame in the KITTI-layout directories, keeps the rig with the most
// frames (ties: the first seen), and loads `maxFrames` of them spread evenly over the listing
// order (all if fewer). Throws std::runtime_error naming the file on unreadable input, and
// std::invalid_argument when no directory holds a frame.
KittiCalibrationInput loadKittiCalibrationInput(const std::vector<std::filesystem::path>& roots, std::size_t maxFrames);

}  // namespace fusedet::fusion
