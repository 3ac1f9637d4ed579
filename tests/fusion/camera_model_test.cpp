// SPDX-License-Identifier: Apache-2.0
// Camera model files, undistortion against a distortion applied here with the Brown-Conrady
// formulas (as OpenCV documents them), and the extrinsics convention.

#include "fusedet/fusion/camera_model.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <random>

#include "fusedet/fusion/undistorter.h"

using namespace fusedet::fusion;

namespace {
const char* kRosYaml = R"(image_width: 640
image_height: 480
camera_name: head_camera
camera_matrix:
  rows: 3
  cols: 3
  data: [500.5, 0, 321.25, 0, 501.5, 239.75, 0, 0, 1]
distortion_model: plumb_bob
distortion_coefficients:
  rows: 1
  cols: 5
  data: [-0.25, 0.08, 0.001, -0.0005, 0.0]
rectification_matrix:
  rows: 3
  cols: 3
  data: [1, 0, 0, 0, 1, 0, 0, 0, 1]
projection_matrix:
  rows: 3
  cols: 4
  data: [500.5, 0, 321.25, 0, 0, 501.5, 239.75, 0, 0, 0, 1, 0]
)";

std::string openCvYaml() {
  cv::FileStorage fs("calib.yaml", cv::FileStorage::WRITE | cv::FileStorage::MEMORY);
  fs << "image_width" << 640 << "image_height" << 480;
  fs << "camera_matrix" << (cv::Mat_<double>(3, 3) << 500.5, 0, 321.25, 0, 501.5, 239.75, 0, 0, 1);
  fs << "distortion_coefficients" << (cv::Mat_<double>(1, 5) << -0.25, 0.08, 0.001, -0.0005, 0.0);
  return fs.releaseAndGetString();
}

void expectModel(const CameraModel& m) {
  EXPECT_EQ(m.width, 640);
  EXPECT_EQ(m.height, 480);
  EXPECT_EQ(m.K(0, 0), 500.5);
  EXPECT_EQ(m.K(1, 1), 501.5);
  EXPECT_EQ(m.K(0, 2), 321.25);
  EXPECT_EQ(m.K(1, 2), 239.75);
  EXPECT_EQ(m.distortion, (std::vector<double>{-0.25, 0.08, 0.001, -0.0005, 0.0}));
  EXPECT_TRUE(m.hasDistortion());
}

// Concatenation instead of std::string::replace: g++ 12 warns falsely (-Wrestrict) on replace.
std::string replaced(const std::string& s, const std::string& from, const std::string& to) {
  const std::size_t p = s.find(from);
  return p == std::string::npos ? s : s.substr(0, p) + to + s.substr(p + from.size());
}

std::string errorOf(const std::string& text) {
  try {
    (void)parseCameraModel(text, "cam.yaml");
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(CameraModel, ReadsRosCameraInfoAndOpenCvCalibration) {
  expectModel(parseCameraModel(kRosYaml));
  const std::string cv = openCvYaml();
  ASSERT_EQ(cv.rfind("%YAML:1.0", 0), 0u);  // what cv::FileStorage really writes
  expectModel(parseCameraModel(cv));
}

TEST(CameraModel, RejectsBadFilesNamingFileAndProblem) {
  EXPECT_NE(errorOf("image_width: 640\n").find("image_height"), std::string::npos);
  EXPECT_NE(errorOf(replaced(kRosYaml, "camera_matrix", "camera_matrixx")).find("camera_matrix"), std::string::npos);
  EXPECT_NE(errorOf(replaced(kRosYaml, "0, 0, 1]", "0, 1]")).find("3x3"), std::string::npos);
  EXPECT_NE(errorOf(replaced(kRosYaml, "plumb_bob", "equidistant")).find("equidistant"), std::string::npos);
  EXPECT_NE(errorOf(replaced(kRosYaml, "[500.5", "[-500.5")).find("focal"), std::string::npos);
  EXPECT_NE(errorOf("a: [1, 2").find("cam.yaml"), std::string::npos);
  EXPECT_NE(errorOf("%YAML:1.0\n---\nimage_width: 640\n").find("cam.yaml"), std::string::npos);
  EXPECT_THROW((void)readCameraModel("/nonexistent/camera.yaml"), std::runtime_error);
}

TEST(CameraModel, FuzzedFilesFailCleanly) {
  std::mt19937 rng(99);
  const std::string seeds[] = {kRosYaml, openCvYaml()};
  int errors = 0;
  for (int iter = 0; iter < 400; ++iter) {
    std::string s = seeds[iter % 2];
    for (int k = 0; k < 1 + static_cast<int>(rng() % 6); ++k) {
      const std::size_t p = rng() % s.size();
      switch (rng() % 3) {
        case 0: s[p] = static_cast<char>(rng()); break;
        case 1: s = s.substr(0, p) + s.substr(std::min(s.size(), p + 1 + rng() % 20)); break;
        default: s.resize(p); break;
      }
      if (s.empty()) s.push_back('x');
    }
    try {
      (void)parseCameraModel(s, "fuzz.yaml");
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("fuzz.yaml"), std::string::npos);
      ++errors;
    }
  }
  EXPECT_GT(errors, 200);
}

namespace {
// OpenCV's documented model (k1 k2 p1 p2 k3): normalised undistorted (x, y) -> distorted.
cv::Point2d distort(double x, double y, const std::vector<double>& d) {
  const double r2 = x * x + y * y;
  const double radial = 1 + d[0] * r2 + d[1] * r2 * r2 + d[4] * r2 * r2 * r2;
  return {x * radial + 2 * d[2] * x * y + d[3] * (r2 + 2 * x * x),
          y * radial + d[2] * (r2 + 2 * y * y) + 2 * d[3] * x * y};
}

cv::Point2d centroid(const cv::Mat& img, cv::Point2d around) {
  double sw = 0, sx = 0, sy = 0;
  for (int y = static_cast<int>(around.y) - 6; y <= static_cast<int>(around.y) + 6; ++y)
    for (int x = static_cast<int>(around.x) - 6; x <= static_cast<int>(around.x) + 6; ++x) {
      const double w = img.at<std::uint8_t>(y, x);
      sw += w;
      sx += w * x;
      sy += w * y;
    }
  return {sx / sw, sy / sw};
}
}  // namespace

TEST(Undistorter, MovesDotsBackToWhereThePinholePutsThem) {
  const CameraModel m = parseCameraModel(kRosYaml);
  const double fx = m.K(0, 0), fy = m.K(1, 1), cx = m.K(0, 2), cy = m.K(1, 2);
  // Ideal (undistorted) dot positions on a grid, rendered as Gaussians at their distorted places.
  std::vector<cv::Point2d> ideal, distorted;
  for (double v = 40.3; v < 460; v += 70)
    for (double u = 40.7; u < 620; u += 90) {
      const cv::Point2d d = distort((u - cx) / fx, (v - cy) / fy, m.distortion);
      ideal.emplace_back(u, v);
      distorted.emplace_back(d.x * fx + cx, d.y * fy + cy);
    }
  cv::Mat img(480, 640, CV_8UC1, cv::Scalar(0));
  for (const cv::Point2d& p : distorted)
    for (int y = static_cast<int>(p.y) - 8; y <= static_cast<int>(p.y) + 8; ++y)
      for (int x = static_cast<int>(p.x) - 8; x <= static_cast<int>(p.x) + 8; ++x)
        if (x >= 0 && y >= 0 && x < 640 && y < 480) {
          const double g = 250 * std::exp(-((x - p.x) * (x - p.x) + (y - p.y) * (y - p.y)) / (2 * 1.5 * 1.5));
          img.at<std::uint8_t>(y, x) = cv::saturate_cast<std::uint8_t>(std::max<double>(img.at<std::uint8_t>(y, x), g));
        }
  const Undistorter u(m);
  EXPECT_FALSE(u.identity());
  const cv::Mat out = u.undistort(img);
  double worst = 0, worstBefore = 0;
  for (std::size_t i = 0; i < ideal.size(); ++i) {
    const cv::Point2d c = centroid(out, ideal[i]);
    worst = std::max(worst, std::hypot(c.x - ideal[i].x, c.y - ideal[i].y));
    worstBefore = std::max(worstBefore, std::hypot(distorted[i].x - ideal[i].x, distorted[i].y - ideal[i].y));
  }
  EXPECT_GT(worstBefore, 20.0);  // the distortion is strong at the corners
  EXPECT_LT(worst, 0.15);
  EXPECT_THROW((void)u.undistort(cv::Mat(10, 10, CV_8UC1)), std::invalid_argument);
  CameraModel none = m;
  none.distortion = {0, 0, 0, 0};
  const Undistorter id(none);
  EXPECT_TRUE(id.identity());
  EXPECT_EQ(id.undistort(img).data, img.data);
}

TEST(CameraModel, ExtrinsicsFollowTheConfigConvention) {
  // Rz(yaw) Ry(pitch) Rx(roll): roll 90 deg alone turns +y into +z; yaw 90 turns +x into +y.
  const auto roll = rigidFromRpyDeg({90, 0, 0}, {1, 2, 3});
  const Eigen::Vector3d p = roll * Eigen::Vector3d(0, 1, 0);
  EXPECT_NEAR(p.x(), 1, 1e-12);
  EXPECT_NEAR(p.y(), 2, 1e-12);
  EXPECT_NEAR(p.z(), 4, 1e-12);
  const auto yawPitch = rigidFromRpyDeg({0, 90, 90}, {0, 0, 0});
  // Ry(90) maps +x to -z; Rz(90) leaves -z alone.
  EXPECT_TRUE((yawPitch * Eigen::Vector3d(1, 0, 0)).isApprox(Eigen::Vector3d(0, 0, -1), 1e-12));
  // Ry(90) maps +z to +x, then Rz(90) maps +x to +y.
  EXPECT_TRUE((yawPitch * Eigen::Vector3d(0, 0, 1)).isApprox(Eigen::Vector3d(0, 1, 0), 1e-12));
}
