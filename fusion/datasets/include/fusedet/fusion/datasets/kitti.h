// SPDX-License-Identifier: Apache-2.0
#pragma once
// Reading one frame of a KITTI-layout directory (image_2/, velodyne/, calib/, label_2/), as the
// object and tracking benchmarks lay it out. Format facts: Geiger et al., IJRR 2013.

#include <Eigen/Core>
#include <filesystem>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/core/label.h"
#include "fusedet/fusion/fuser.h"
#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

struct KittiCalib {
  Eigen::Matrix<double, 3, 4> P2;          // rectified projection of the left colour camera
  Eigen::Matrix3d R0rect;                  // rectifying rotation
  Eigen::Matrix<double, 3, 4> TrVeloToCam; // Velodyne -> camera 0
  // x_image ~ P2 * R0rect * TrVeloToCam * X_velo (homogeneous)
  Eigen::Matrix<double, 3, 4> veloToImage() const;
};

// How KITTI classes map onto project classes. Unlisted classes become ignore regions.
struct KittiClassMap {
  // source class -> project class; "" marks an ignore region
  std::vector<std::pair<std::string, std::string>> entries = {
      {"Car", "car"},         {"Pedestrian", "person"}, {"Cyclist", "bike"},
      {"Van", "van"},         {"Truck", ""},            {"Tram", ""},
      {"Misc", ""},           {"Person_sitting", ""},   {"DontCare", ""}};
};

struct KittiFrame {
  std::string id;       // "000042"
  cv::Mat image;        // BGR, 8-bit
  Sweep points;         // Velodyne points in the Velodyne frame, remission = KITTI reflectance
  KittiCalib calib;
  Labels labels;
};

// Frame ids of a KITTI directory: ImageSets/all.txt if present, else the sorted image_2/*.png stems.
std::vector<std::string> listKittiFrames(const std::filesystem::path& root);

// Throws std::runtime_error naming the file and the problem on missing or malformed input.
KittiCalib readKittiCalib(const std::filesystem::path& file);
Labels readKittiLabels(const std::filesystem::path& file, const KittiClassMap& map = {});
Sweep readKittiVelodyne(const std::filesystem::path& file);
KittiFrame readKittiFrame(const std::filesystem::path& root, const std::string& id,
                          const KittiClassMap& map = {});

// The rectified colour camera of a KITTI frame as a pinhole + rigid transform, so KITTI goes
// through the same projection code as live data: K = P2(:, 0:3), and the camera-2 frame is
// [I | K^-1 P2(:, 3)] * R0_rect * Tr_velo_to_cam, hence K * (T * X) = P2 * R0_rect * Tr * X.
PinholeProjection kittiProjection(const KittiCalib& calib, int width, int height);
// A Fuser for a KITTI camera (no distortion: image_2 is rectified).
// `neural` (optional): the network whose score layers the stacks also get.
Fuser kittiFuser(const KittiCalib& calib, int width, int height, const ProjectionConfig& config = {},
                 std::shared_ptr<const NeuralLayers> neural = {});

}  // namespace fusedet::fusion
