// SPDX-License-Identifier: Apache-2.0
// The pieces under the calibrations: Nelder-Mead, the rpy convention's inverse, the extrinsics
// file, and the KITTI calibration input.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "fusedet/fusion/calibration/calib_kitti.h"
#include "fusedet/fusion/calibration/calib_targetless.h"
#include "fusedet/fusion/calibration/extrinsics_file.h"
#include "fusedet/fusion/calibration/nelder_mead.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {
namespace {

TEST(NelderMead, FindsTheMinimumOfRosenbrock) {
  int calls = 0;
  auto rosen = [&](const Eigen::VectorXd& x) {
    ++calls;
    return 100 * std::pow(x(1) - x(0) * x(0), 2) + std::pow(1 - x(0), 2);
  };
  NelderMeadOptions o;
  o.maxEvaluations = 5000;
  o.xTolerance = 1e-8;
  o.fTolerance = 1e-14;
  const NelderMeadResult r = minimiseNelderMead(rosen, Eigen::Vector2d(-1.2, 1.0), Eigen::Vector2d(0.5, 0.5), o);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.x(0), 1.0, 1e-4);
  EXPECT_NEAR(r.x(1), 1.0, 1e-4);
  EXPECT_EQ(r.evaluations, calls);
}

TEST(NelderMead, StopsAtTheEvaluationBudget) {
  auto bowl = [](const Eigen::VectorXd& x) { return x.squaredNorm(); };
  NelderMeadOptions o;
  o.maxEvaluations = 20;
  o.xTolerance = 0;
  o.fTolerance = 0;
  const NelderMeadResult r = minimiseNelderMead(bowl, Eigen::VectorXd::Constant(6, 3.0), Eigen::VectorXd::Ones(6), o);
  EXPECT_FALSE(r.converged);
  EXPECT_LE(r.evaluations, 20 + 6);  // a shrink step may finish after the budget is reached
  EXPECT_LT(r.value, 54.0);
  EXPECT_THROW((void)minimiseNelderMead(bowl, Eigen::VectorXd::Ones(2), Eigen::VectorXd::Ones(3)), std::invalid_argument);
}

TEST(Extrinsics, RpyRoundTripsIncludingGimbalLock) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> angle(-180, 180), pitch(-90, 90);
  std::vector<std::array<double, 3>> cases = {{0, 0, 0}, {-90, 0, -90}, {30, 90, 10}, {0, -90, 45}, {12, -89.9999, 3}};
  for (int i = 0; i < 200; ++i) cases.push_back({angle(rng), pitch(rng), angle(rng)});
  for (const auto& rpy : cases) {
    const Eigen::Isometry3d T = rigidFromRpyDeg(rpy, {0, 0, 0});
    const Eigen::Isometry3d back = rigidFromRpyDeg(rpyDegFromRotation(T.linear()), {0, 0, 0});
    EXPECT_LT((back.linear() - T.linear()).cwiseAbs().maxCoeff(), 1e-9) << rpy[0] << " " << rpy[1] << " " << rpy[2];
  }
  // A KITTI-like Velodyne -> camera rotation sits at pitch -90 (gimbal lock): roll is reported 0.
  Eigen::Matrix3d kitti;
  kitti << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  const auto rpy = rpyDegFromRotation(kitti);
  EXPECT_NEAR(rpy[0], 0, 1e-9);
  EXPECT_NEAR(rpy[1], -90, 1e-9);
  EXPECT_NEAR(rpy[2], 90, 1e-9);
}

TEST(Extrinsics, FileRoundTripsAndIsAConfigFragment) {
  const Eigen::Isometry3d T = rigidFromRpyDeg({-88.5, -0.7, -91.2}, {0.06, -0.08, -0.27});
  const std::string text = formatLaserToCamera(T, "line one\nline two");
  EXPECT_EQ(text.rfind("# line one\n# line two\nfusion:\n  laser_to_camera:\n    rotation_rpy_deg: [", 0), 0u) << text;
  const Eigen::Isometry3d back = parseLaserToCamera(text);
  EXPECT_LT(rotationErrorDeg(back, T), 1e-7);
  EXPECT_LT(translationError(back, T), 1e-8);
  const auto file = std::filesystem::path(FUSEDET_BINARY_DIR) / "extrinsics_roundtrip.yaml";
  writeLaserToCamera(file, T);
  EXPECT_LT(rotationErrorDeg(readLaserToCamera(file), T), 1e-7);
  // The shipped config's block reads back as the config convention says.
  const Eigen::Isometry3d shipped = readLaserToCamera(std::filesystem::path(FUSEDET_SOURCE_DIR) / "config/fusedet.yaml");
  EXPECT_LT(rotationErrorDeg(shipped, rigidFromRpyDeg({-90, 0, -90}, {0, -0.10, 0})), 1e-9);
}

TEST(Extrinsics, BadFilesGiveClearErrors) {
  auto message = [](const std::string& yaml) {
    try {
      (void)parseLaserToCamera(yaml, "x.yaml");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  EXPECT_NE(message("fusion: [").find("x.yaml: not valid YAML"), std::string::npos);
  EXPECT_NE(message("log: {level: info}").find("no fusion.laser_to_camera"), std::string::npos);
  EXPECT_NE(message("fusion: {laser_to_camera: {translation: [0, 0, 0]}}").find("no key fusion.laser_to_camera.rotation_rpy_deg"),
            std::string::npos);
  EXPECT_NE(message("fusion: {laser_to_camera: {rotation_rpy_deg: [1, 2], translation: [0, 0, 0]}}").find("list of 3"),
            std::string::npos);
  EXPECT_NE(message("fusion: {laser_to_camera: {rotation_rpy_deg: [1, a, 3], translation: [0, 0, 0]}}")
                .find("rotation_rpy_deg[1] is not a number"),
            std::string::npos);
  EXPECT_NE(message("fusion: {laser_to_camera: {rotation_rpy_deg: [1, 2, .nan], translation: [0, 0, 0]}}").find("not finite"),
            std::string::npos);
  // Garbage of every length never crashes the reader.
  std::mt19937 rng(5);
  for (int i = 0; i < 300; ++i) {
    std::string junk(static_cast<std::size_t>(rng() % 80), ' ');
    for (char& c : junk) c = static_cast<char>(rng() % 96 + 32);
    EXPECT_NE(message(junk), "accepted") << junk;
  }
  EXPECT_THROW((void)readLaserToCamera("/nonexistent/extrinsics.yaml"), std::runtime_error);
}

TEST(KittiCalibrationInput, KeepsOneRigAndSpreadsFrames) {
  const std::filesystem::path data = FUSEDET_DATA_DIR;
  const KittiCalibrationInput in =
      loadKittiCalibrationInput({data / "kitti", data / "kitti_object_more", data / "kitti_object_sample"}, 4);
  ASSERT_EQ(in.frames.size(), 4u);
  // 52 frames of drive 0005, 19 of kitti_object_more and 2 of kitti_object_sample are 2011_09_26.
  EXPECT_EQ(in.rigFrames, 52u + 19u + 2u);
  EXPECT_EQ(in.otherRigFrames, 4u + 1u);
  EXPECT_EQ(in.frames.front().name, "kitti/000000");
  EXPECT_EQ(in.frames.back().name, "kitti_object_sample/000002");
  // The transform is the calib's Velodyne -> rectified camera 2 (P2 = K [I | K^-1 P2(:,3)]).
  const Eigen::Vector3d p(10.0, 1.0, -1.0);
  const Eigen::Vector3d viaTransform = in.K * (in.laserToCamera * p);
  const Eigen::Vector3d viaCalib = in.calib.veloToImage() * p.homogeneous();
  EXPECT_LT((viaTransform.hnormalized() - viaCalib.hnormalized()).norm(), 1e-9);
  EXPECT_THROW((void)loadKittiCalibrationInput({data / "does-not-exist"}, 4), std::runtime_error);
}

}  // namespace
}  // namespace fusedet::fusion
