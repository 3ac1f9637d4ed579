// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/kitti.h"

#include <algorithm>
#include <cstring>
#include <fstream>
#include <optional>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <stdexcept>

#include "fusedet/fusion/datasets/box_corners.h"

namespace fusedet::fusion {
namespace fs = std::filesystem;

namespace {

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
  throw std::runtime_error(file.string() + ": " + what);
}

// Reads "KEY: v1 v2 ... vn" into a row-major matrix; fails if the key is missing or short.
template <int R, int C>
Eigen::Matrix<double, R, C> readMatrix(const fs::path& file, const std::string& text,
                                       const std::string& key) {
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    if (line.rfind(key + ":", 0) != 0) continue;
    std::istringstream values(line.substr(key.size() + 1));
    Eigen::Matrix<double, R, C> m;
    for (int r = 0; r < R; ++r)
      for (int c = 0; c < C; ++c)
        if (!(values >> m(r, c)))
          fail(file, key + " has fewer than " + std::to_string(R * C) + " numbers");
    return m;
  }
  fail(file, "no line '" + key + ":'");
}

}  // namespace

Eigen::Matrix<double, 3, 4> KittiCalib::veloToImage() const {
  Eigen::Matrix4d tr = Eigen::Matrix4d::Identity();
  tr.topRows<3>() = TrVeloToCam;
  Eigen::Matrix4d r0 = Eigen::Matrix4d::Identity();
  r0.topLeftCorner<3, 3>() = R0rect;
  return P2 * r0 * tr;
}

PinholeProjection kittiProjection(const KittiCalib& calib, int width, int height) {
  PinholeProjection p;
  p.K = calib.P2.leftCols<3>();
  if (p.K(2, 0) != 0 || p.K(2, 1) != 0 || p.K(2, 2) != 1 || p.K(1, 0) != 0 || !(p.K(0, 0) > 0) || !(p.K(1, 1) > 0))
    throw std::runtime_error("KITTI P2 is not of the form K [I | t] with K upper triangular");
  Eigen::Isometry3d shift = Eigen::Isometry3d::Identity();
  shift.translation() = p.K.inverse() * calib.P2.col(3);
  Eigen::Isometry3d rect = Eigen::Isometry3d::Identity();
  rect.linear() = calib.R0rect;
  Eigen::Isometry3d velo = Eigen::Isometry3d::Identity();
  velo.matrix().topRows<3>() = calib.TrVeloToCam;
  p.sweepToCamera = shift * rect * velo;
  // A focal length near 0 (or huge entries) passes the form check but K^-1 P2(:, 3) overflows:
  // every projected point would be inf / NaN.
  if (!p.sweepToCamera.matrix().allFinite())
    throw std::runtime_error("KITTI calib: P2, R0_rect and Tr_velo_to_cam give a non-finite transform (K nearly singular?)");
  p.width = width;
  p.height = height;
  return p;
}

Fuser kittiFuser(const KittiCalib& calib, int width, int height, const ProjectionConfig& config,
                 std::shared_ptr<const NeuralLayers> neural) {
  const PinholeProjection p = kittiProjection(calib, width, height);
  CameraModel camera;
  camera.width = width;
  camera.height = height;
  camera.K = p.K;
  return Fuser(camera, p.sweepToCamera, config, std::move(neural));
}

std::vector<std::string> listKittiFrames(const fs::path& root) {
  std::vector<std::string> ids;
  if (std::ifstream list(root / "ImageSets" / "all.txt"); list) {
    for (std::string id; list >> id;) ids.push_back(id);
    return ids;
  }
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(root / "image_2", ec))
    if (entry.path().extension() == ".png") ids.push_back(entry.path().stem().string());
  if (ec) throw std::runtime_error((root / "image_2").string() + ": " + ec.message());
  std::sort(ids.begin(), ids.end());
  return ids;
}

KittiCalib readKittiCalib(const fs::path& file) {
  std::ifstream in(file);
  if (!in) fail(file, "cannot open calibration file");
  std::stringstream text;
  text << in.rdbuf();
  KittiCalib calib;
  calib.P2 = readMatrix<3, 4>(file, text.str(), "P2");
  // The raw-data layout calls it R_rect / Tr_velo_cam; the object layout R0_rect / Tr_velo_to_cam.
  calib.R0rect = readMatrix<3, 3>(file, text.str(), "R0_rect");
  calib.TrVeloToCam = readMatrix<3, 4>(file, text.str(), "Tr_velo_to_cam");
  return calib;
}

Labels readKittiLabels(const fs::path& file, const KittiClassMap& map) {
  std::ifstream in(file);
  if (!in) fail(file, "cannot open label file");
  Labels labels;
  std::string line;
  for (int lineNo = 1; std::getline(in, line); ++lineNo) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    std::istringstream f(line);
    Label l;
    double alpha = 0, x1 = 0, y1 = 0, x2 = 0, y2 = 0;
    if (!(f >> l.sourceClass >> l.truncation >> l.occlusion >> alpha >> x1 >> y1 >> x2 >> y2))
      fail(file, "line " + std::to_string(lineNo) + ": expected class, truncated, occluded, alpha, bbox");
    const std::optional<Box> box = boxFromCorners(x1, y1, x2, y2);
    if (!box) fail(file, "line " + std::to_string(lineNo) + ": box has a negative or non-finite size");
    l.box = *box;
    l.ignore = true;
    l.className = l.sourceClass;
    for (const auto& [src, dst] : map.entries) {
      if (src != l.sourceClass) continue;
      l.ignore = dst.empty();
      if (!dst.empty()) l.className = dst;
    }
    labels.push_back(std::move(l));
  }
  return labels;
}

Sweep readKittiVelodyne(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) fail(file, "cannot open Velodyne file");
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (bytes.size() % (4 * sizeof(float)) != 0)
    fail(file, "size " + std::to_string(bytes.size()) + " is not a multiple of 16 bytes (x,y,z,r float32)");
  Sweep sweep;
  sweep.frame = Sweep::Frame::kVelodyne;
  const std::size_t n = bytes.size() / (4 * sizeof(float));
  sweep.points.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    float v[4];
    std::memcpy(v, bytes.data() + i * sizeof v, sizeof v);
    sweep.points[i] = SweepPoint{v[0], v[1], v[2], v[3], 0};
  }
  return sweep;
}

KittiFrame readKittiFrame(const fs::path& root, const std::string& id, const KittiClassMap& map) {
  KittiFrame frame;
  frame.id = id;
  const fs::path image = root / "image_2" / (id + ".png");
  frame.image = cv::imread(image.string(), cv::IMREAD_COLOR);
  if (frame.image.empty()) fail(image, "cannot read image");
  frame.points = readKittiVelodyne(root / "velodyne" / (id + ".bin"));
  frame.calib = readKittiCalib(root / "calib" / (id + ".txt"));
  frame.labels = readKittiLabels(root / "label_2" / (id + ".txt"), map);
  return frame;
}

}  // namespace fusedet::fusion
