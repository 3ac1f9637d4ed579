// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/camera_model.h"

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <opencv2/core.hpp>
#include <sstream>
#include <stdexcept>

namespace fusedet::fusion {
namespace {

[[noreturn]] void fail(const std::string& what, const std::string& problem) {
  throw std::runtime_error(what + ": " + problem);
}

// Shared checks: sane size, K a pinhole (positive focal lengths, last row 0 0 1), finite
// coefficients, a count OpenCV knows.
void validate(CameraModel& m, const std::string& what) {
  if (m.width <= 0 || m.height <= 0 || m.width > 65536 || m.height > 65536)
    fail(what, "image size " + std::to_string(m.width) + "x" + std::to_string(m.height) + " is not valid");
  if (!m.K.allFinite() || !(m.K(0, 0) > 0) || !(m.K(1, 1) > 0))
    fail(what, "camera_matrix needs positive, finite focal lengths");
  if (m.K(1, 0) != 0 || m.K(2, 0) != 0 || m.K(2, 1) != 0 || m.K(2, 2) != 1)
    fail(what, "camera_matrix must be [fx s cx; 0 fy cy; 0 0 1]");
  for (double d : m.distortion)
    if (!std::isfinite(d)) fail(what, "distortion coefficients must be finite");
  const std::size_t n = m.distortion.size();
  if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14)
    fail(what, std::to_string(n) + " distortion coefficients; OpenCV takes 4, 5, 8, 12 or 14");
}

std::vector<double> rosMatrix(const YAML::Node& root, const std::string& key, const std::string& what,
                              int rows, int cols) {
  const YAML::Node m = root[key];
  if (!m || !m.IsMap()) fail(what, "no '" + key + "' map");
  const YAML::Node data = m["data"];
  if (!data || !data.IsSequence()) fail(what, key + ".data must be a list");
  const int r = m["rows"] ? m["rows"].as<int>() : -1, c = m["cols"] ? m["cols"].as<int>() : -1;
  std::vector<double> out;
  for (const auto& v : data) out.push_back(v.as<double>());
  if (rows > 0 && (r != rows || c != cols || out.size() != static_cast<std::size_t>(rows * cols)))
    fail(what, key + " must be " + std::to_string(rows) + "x" + std::to_string(cols));
  if (rows < 0 && (r < 0 || c < 0 || out.size() != static_cast<std::size_t>(r) * static_cast<std::size_t>(c)))
    fail(what, key + ": rows*cols does not match the data length");
  return out;
}

CameraModel parseRos(const std::string& text, const std::string& what) {
  CameraModel m;
  try {
    const YAML::Node root = YAML::Load(text);
    if (!root.IsMap()) fail(what, "top level is not a YAML map");
    if (!root["image_width"] || !root["image_height"]) fail(what, "no image_width / image_height");
    m.width = root["image_width"].as<int>();
    m.height = root["image_height"].as<int>();
    const auto k = rosMatrix(root, "camera_matrix", what, 3, 3);
    for (int i = 0; i < 9; ++i) m.K(i / 3, i % 3) = k[static_cast<std::size_t>(i)];
    const std::string model = root["distortion_model"] ? root["distortion_model"].as<std::string>() : "plumb_bob";
    if (model != "plumb_bob" && model != "rational_polynomial")
      fail(what, "distortion_model '" + model + "' is not plumb_bob or rational_polynomial");
    if (root["distortion_coefficients"]) m.distortion = rosMatrix(root, "distortion_coefficients", what, -1, -1);
  } catch (const YAML::Exception& e) {
    fail(what, std::string("YAML: ") + e.what());
  }
  return m;
}

CameraModel parseOpenCv(const std::string& text, const std::string& what) {
  CameraModel m;
  try {
    cv::FileStorage fs(text, cv::FileStorage::READ | cv::FileStorage::MEMORY);
    if (!fs.isOpened()) fail(what, "cannot parse as OpenCV YAML");
    const cv::FileNode w = fs["image_width"], h = fs["image_height"];
    if (!w.isInt() || !h.isInt()) fail(what, "no integer image_width / image_height");
    m.width = static_cast<int>(w);
    m.height = static_cast<int>(h);
    cv::Mat k, d;
    fs["camera_matrix"] >> k;
    if (k.rows != 3 || k.cols != 3 || k.channels() != 1) fail(what, "camera_matrix must be a 3x3 matrix");
    k.convertTo(k, CV_64F);
    for (int i = 0; i < 9; ++i) m.K(i / 3, i % 3) = k.at<double>(i / 3, i % 3);
    fs["distortion_coefficients"] >> d;
    if (!d.empty()) {
      if ((d.rows != 1 && d.cols != 1) || d.channels() != 1) fail(what, "distortion_coefficients must be a vector");
      d.convertTo(d, CV_64F);
      m.distortion.assign(d.ptr<double>(), d.ptr<double>() + d.total());
    }
  } catch (const cv::Exception& e) {
    fail(what, std::string("OpenCV YAML: ") + e.what());
  }
  return m;
}

}  // namespace

bool CameraModel::hasDistortion() const {
  for (double d : distortion)
    if (d != 0) return true;
  return false;
}

CameraModel parseCameraModel(const std::string& text, const std::string& what) {
  // cv::FileStorage writes "%YAML:1.0" (not YAML 1.2) and !!opencv-matrix tags; ROS files are
  // plain YAML maps.
  const bool opencv = text.rfind("%YAML:1.", 0) == 0 || text.find("!!opencv-matrix") != std::string::npos;
  CameraModel m = opencv ? parseOpenCv(text, what) : parseRos(text, what);
  validate(m, what);
  return m;
}

std::string formatCameraModel(const CameraModel& m, const std::string& cameraName, const std::string& comment) {
  auto number = [](double v) {
    char buf[40];
    std::snprintf(buf, sizeof buf, "%.17g", v);
    return std::string(buf);
  };
  auto matrix = [&](const std::string& key, int rows, int cols, const std::vector<double>& data) {
    std::string out = key + ":\n  rows: " + std::to_string(rows) + "\n  cols: " + std::to_string(cols) + "\n  data: [";
    for (std::size_t i = 0; i < data.size(); ++i) out += (i ? ", " : "") + number(data[i]);
    return out + "]\n";
  };
  std::string out;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);) out += "# " + line + "\n";
  out += "image_width: " + std::to_string(m.width) + "\nimage_height: " + std::to_string(m.height) + "\n";
  out += "camera_name: " + cameraName + "\n";
  std::vector<double> k(9), p(12, 0.0);
  for (int i = 0; i < 9; ++i) k[static_cast<std::size_t>(i)] = m.K(i / 3, i % 3);
  for (int r = 0; r < 3; ++r)
    for (int col = 0; col < 3; ++col) p[static_cast<std::size_t>(4 * r + col)] = m.K(r, col);
  out += matrix("camera_matrix", 3, 3, k);
  out += std::string("distortion_model: ") + (m.distortion.size() <= 5 ? "plumb_bob" : "rational_polynomial") + "\n";
  out += matrix("distortion_coefficients", 1, static_cast<int>(m.distortion.size()), m.distortion);
  out += matrix("rectification_matrix", 3, 3, {1, 0, 0, 0, 1, 0, 0, 0, 1});
  out += matrix("projection_matrix", 3, 4, p);
  return out;
}

CameraModel readCameraModel(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) fail(file.string(), "cannot open camera calibration");
  std::stringstream text;
  text << in.rdbuf();
  return parseCameraModel(text.str(), file.string());
}

Eigen::Isometry3d rigidFromRpyDeg(const std::array<double, 3>& rpyDeg, const std::array<double, 3>& translation) {
  constexpr double kDeg = M_PI / 180.0;
  const Eigen::Matrix3d R = (Eigen::AngleAxisd(rpyDeg[2] * kDeg, Eigen::Vector3d::UnitZ()) *
                             Eigen::AngleAxisd(rpyDeg[1] * kDeg, Eigen::Vector3d::UnitY()) *
                             Eigen::AngleAxisd(rpyDeg[0] * kDeg, Eigen::Vector3d::UnitX()))
                                .toRotationMatrix();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  T.translation() = Eigen::Vector3d(translation[0], translation[1], translation[2]);
  return T;
}

std::array<double, 3> rpyDegFromRotation(const Eigen::Matrix3d& R) {
  constexpr double kRad = 180.0 / M_PI;
  // R = Rz(y) Ry(p) Rx(r): R(2,0) = -sin p, R(2,1) = cos p sin r, R(2,2) = cos p cos r,
  // R(1,0) = sin y cos p, R(0,0) = cos y cos p.
  const double cosPitch = std::hypot(R(0, 0), R(1, 0));
  const double pitch = std::atan2(-R(2, 0), cosPitch);
  if (cosPitch < 1e-12) {  // gimbal lock: R(0,1) = -sin(y -+ r), R(1,1) = cos(y -+ r)
    return {0.0, pitch * kRad, std::atan2(-R(0, 1), R(1, 1)) * kRad};
  }
  return {std::atan2(R(2, 1), R(2, 2)) * kRad, pitch * kRad, std::atan2(R(1, 0), R(0, 0)) * kRad};
}

}  // namespace fusedet::fusion
