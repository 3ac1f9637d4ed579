// SPDX-License-Identifier: Apache-2.0
// Camera intrinsics from chessboard views (fusedet calibrate-camera): the distortion model and the
// fit checked against OpenCV's own implementations (cv::projectPoints, cv::calibrateCamera), on
// synthetic views and on the real photographs Debian ships with OpenCV's samples (opencv-doc).

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <random>

#include "fusedet/fusion/calibration/board_corners.h"
#include "fusedet/fusion/calibration/camera_intrinsics.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {
namespace {

namespace fs = std::filesystem;

const fs::path kSamples = "/usr/share/doc/opencv-doc/examples/data";

cv::Mat cvK(const Eigen::Matrix3d& K) {
  return (cv::Mat_<double>(3, 3) << K(0, 0), K(0, 1), K(0, 2), K(1, 0), K(1, 1), K(1, 2), 0, 0, 1);
}

TEST(CameraIntrinsics, ProjectionIsOpenCvsDistortionModel) {
  CameraModel c;
  c.width = 640, c.height = 480;
  c.K << 810.5, 0, 321.25, 0, 790.75, 244.5, 0, 0, 1;
  c.distortion = {-0.28, 0.11, 0.0013, -0.0021, -0.03};
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> xy(-1.5, 1.5), z(1.0, 4.0);
  std::vector<cv::Point3d> points;
  for (int i = 0; i < 200; ++i) points.emplace_back(xy(rng), xy(rng), z(rng));
  std::vector<cv::Point2d> theirs;
  cv::projectPoints(points, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), cvK(c.K), c.distortion, theirs);
  for (std::size_t i = 0; i < points.size(); ++i) {
    const Eigen::Vector2d ours = projectPoint(c, Eigen::Vector3d(points[i].x, points[i].y, points[i].z));
    EXPECT_NEAR(ours.x(), theirs[i].x, 1e-9 * std::max(1.0, std::abs(theirs[i].x))) << i;
    EXPECT_NEAR(ours.y(), theirs[i].y, 1e-9 * std::max(1.0, std::abs(theirs[i].y))) << i;
  }
}

// Views made by OpenCV's projection of a known camera, with 0.1 px of noise: the fit recovers it.
TEST(CameraIntrinsics, RecoversAKnownCameraFromSyntheticViews) {
  const BoardSpec board{9, 6, 0.03};
  const std::vector<cv::Point3f> points = boardPoints(board);
  const Eigen::Matrix3d K = (Eigen::Matrix3d() << 800, 0, 330, 0, 780, 250, 0, 0, 1).finished();
  const std::vector<double> dist = {-0.21, 0.09, 0.0011, -0.0007, 0.0};
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 0.1);
  std::uniform_real_distribution<double> tilt(-0.6, 0.6), spin(-0.4, 0.4), shift(-0.12, 0.05), depth(0.55, 0.9);
  std::vector<std::vector<cv::Point2f>> views;
  while (views.size() < 10) {
    const cv::Vec3d r(tilt(rng), tilt(rng), spin(rng)), t(shift(rng), shift(rng) * 0.8, depth(rng));
    std::vector<cv::Point2f> uv;
    cv::projectPoints(points, r, t, cvK(K), dist, uv);
    bool inside = true;
    for (auto& p : uv) {
      p.x += static_cast<float>(noise(rng)), p.y += static_cast<float>(noise(rng));
      inside = inside && p.x > 5 && p.y > 5 && p.x < 635 && p.y < 475;
    }
    if (inside) views.push_back(uv);
  }
  const IntrinsicsResult r = calibrateIntrinsics(views, board, {640, 480});
  const double truth[9] = {800, 780, 330, 250, -0.21, 0.09, 0.0011, -0.0007, 0.0};
  const double fit[9] = {r.camera.K(0, 0), r.camera.K(1, 1), r.camera.K(0, 2), r.camera.K(1, 2), r.camera.distortion[0],
                         r.camera.distortion[1], r.camera.distortion[2], r.camera.distortion[3], r.camera.distortion[4]};
  for (int k = 0; k < 9; ++k) {
    EXPECT_NEAR(fit[k], truth[k], 3.5 * r.sigma(k)) << "parameter " << k << ": within 3.5 of its own 1-sigma";
  }
  EXPECT_LT(r.sigma(0), 0.01 * 800) << "focal length to 1 %";
  EXPECT_NEAR(r.rmsPx, 0.1 * std::sqrt(2.0), 0.03) << "the noise put in, per corner (x and y)";
  for (int k = 0; k < 4; ++k) EXPECT_GT(r.sigma(k), 0.0);
  EXPECT_LT(r.sigma(0), 3.0);
  ASSERT_EQ(r.boardToCamera.size(), views.size());
  ASSERT_EQ(r.viewRmsPx.size(), views.size());
}

TEST(CameraIntrinsics, RefusesTooFewViewsAndBadBoards) {
  const BoardSpec board{9, 6, 0.025};
  const std::vector<std::vector<cv::Point2f>> two(2, std::vector<cv::Point2f>(54));
  try {
    calibrateIntrinsics(two, board, {640, 480});
    FAIL() << "2 views accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("3 or more"), std::string::npos) << e.what();
  }
  EXPECT_THROW(parseBoardSize("9x", 0.025), std::invalid_argument);
  EXPECT_THROW(parseBoardSize("2x6", 0.025), std::invalid_argument);
  EXPECT_THROW(parseBoardSize("9x6x1", 0.025), std::invalid_argument);
  EXPECT_THROW(parseBoardSize("9x6", 0.0), std::invalid_argument);
  const BoardSpec b = parseBoardSize("7x5", 0.04);
  EXPECT_EQ(b.cols, 7);
  EXPECT_EQ(b.rows, 5);
  EXPECT_THROW(findBoardCorners(fs::path(__FILE__), b, nullptr), std::runtime_error) << "not an image";
}

TEST(CameraIntrinsics, TheWrittenFileReadsBackExactly) {
  CameraModel c;
  c.width = 640, c.height = 480;
  c.K << 535.915733961632, 0, 342.283154733084, 0, 535.915733961632, 235.570829097882, 0, 0, 1;
  c.distortion = {-0.266372609096607, -0.0385888989223047, 0.00178319470428530, -0.000281221004411155, 0.238391530808785};
  const CameraModel back = parseCameraModel(formatCameraModel(c, "left", "fit\nof 13 views"), "written");
  EXPECT_EQ(back.width, 640);
  EXPECT_EQ(back.height, 480);
  EXPECT_EQ(back.K, c.K);
  EXPECT_EQ(back.distortion, c.distortion);
}

// OpenCV's sample photographs (a 9x6 board, 640x480, left01-14 without 10): our corners, fitted
// by our solver and by cv::calibrateCamera (default flags: the same nine intrinsics), agree.
TEST(CameraIntrinsics, OpenCvSamplePhotographsGiveOpenCvsIntrinsics) {
  if (!fs::exists(kSamples / "left01.jpg")) GTEST_SKIP() << "opencv-doc is not installed (scripts/deps installs it)";
  const BoardSpec board{9, 6, 0.025};
  std::vector<std::vector<cv::Point2f>> views;
  int images = 0;
  cv::Size size;
  for (const char* n : {"01", "02", "03", "04", "05", "06", "07", "08", "09", "11", "12", "13", "14"}) {
    ++images;
    if (auto c = findBoardCorners(kSamples / (std::string("left") + n + ".jpg"), board, &size)) views.push_back(*c);
  }
  EXPECT_EQ(views.size(), 13u) << "the board is whole in every sample photograph";
  ASSERT_GE(views.size(), 3u);
  const IntrinsicsResult ours = calibrateIntrinsics(views, board, size);

  std::vector<std::vector<cv::Point3f>> object(views.size(), boardPoints(board));
  cv::Mat K, dist;
  std::vector<cv::Mat> rv, tv;
  const double theirRms = cv::calibrateCamera(object, views, size, K, dist, rv, tv);
  EXPECT_NEAR(ours.rmsPx, theirRms, 1e-3);
  EXPECT_NEAR(ours.camera.K(0, 0), K.at<double>(0, 0), 1e-3 * K.at<double>(0, 0));
  EXPECT_NEAR(ours.camera.K(1, 1), K.at<double>(1, 1), 1e-3 * K.at<double>(1, 1));
  EXPECT_NEAR(ours.camera.K(0, 2), K.at<double>(0, 2), 0.5);
  EXPECT_NEAR(ours.camera.K(1, 2), K.at<double>(1, 2), 0.5);
  for (int k = 0; k < 5; ++k) EXPECT_NEAR(ours.camera.distortion[static_cast<std::size_t>(k)], dist.at<double>(k), 0.01) << k;
  EXPECT_LT(ours.rmsPx, 0.5) << "sub-pixel corners";
}

}  // namespace
}  // namespace fusedet::fusion
