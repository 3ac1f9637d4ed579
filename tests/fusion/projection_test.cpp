// SPDX-License-Identifier: Apache-2.0
// Projection and laser layers, checked against computations written here from the KITTI
// definition x = P2 * R0_rect * Tr_velo_to_cam * X (Geiger et al., IJRR 2013).

#include "fusedet/fusion/projection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <opencv2/core.hpp>
#include <sstream>

#include "fusedet/fusion/datasets/kitti.h"

namespace fs = std::filesystem;
using namespace fusedet;
using namespace fusedet::fusion;

namespace {
const fs::path kData = fs::path(FUSEDET_DATA_DIR);

// Calibration parsed here, independently of readKittiCalib.
struct Calib {
  Eigen::Matrix<double, 3, 4> P2;
  Eigen::Matrix4d R0 = Eigen::Matrix4d::Identity(), Tr = Eigen::Matrix4d::Identity();
};
Calib parseCalib(const fs::path& file) {
  std::ifstream in(file);
  std::string line;
  Calib c;
  while (std::getline(in, line)) {
    std::istringstream s(line);
    std::string key;
    s >> key;
    if (key == "P2:")
      for (int i = 0; i < 12; ++i) s >> c.P2(i / 4, i % 4);
    if (key == "R0_rect:")
      for (int i = 0; i < 9; ++i) s >> c.R0(i / 3, i % 3);
    if (key == "Tr_velo_to_cam:")
      for (int i = 0; i < 12; ++i) s >> c.Tr(i / 4, i % 4);
  }
  return c;
}

struct Expected {
  double u, v, z, range;
};
// Every point, projected the textbook way; range = distance from the camera-2 centre, which is
// C = -M^-1 p4 for P2 = [M | p4] in rectified camera-0 coordinates.
std::vector<Expected> expectedProjection(const Sweep& sweep, const Calib& c) {
  const Eigen::Matrix<double, 3, 4> P = c.P2 * c.R0 * c.Tr;
  const Eigen::Vector3d centre = -c.P2.leftCols<3>().inverse() * c.P2.col(3);
  std::vector<Expected> out;
  for (const SweepPoint& p : sweep.points) {
    const Eigen::Vector4d X(p.x, p.y, p.z, 1);
    const Eigen::Vector3d x = P * X;
    const Eigen::Vector3d rect = (c.R0 * c.Tr * X).head<3>();
    out.push_back({x(0) / x(2), x(1) / x(2), x(2), (rect - centre).norm()});
  }
  return out;
}

bool inImage(const Expected& e, int w, int h, double minDepth) {
  return e.z >= minDepth && e.u >= 0 && e.u < w && e.v >= 0 && e.v < h;
}

void checkKittiFrame(const std::string& drive, const std::string& id) {
  SCOPED_TRACE(drive + "/" + id);
  const KittiFrame f = readKittiFrame(kData / drive, id);
  const Calib c = parseCalib(kData / drive / "calib" / (id + ".txt"));
  const int w = f.image.cols, h = f.image.rows;
  const auto expected = expectedProjection(f.points, c);
  const auto got = projectPoints(f.points, kittiProjection(f.calib, w, h), 0.05);
  std::size_t expectedIn = 0;
  for (const Expected& e : expected) expectedIn += inImage(e, w, h, 0.05) ? 1 : 0;
  EXPECT_GT(expectedIn, 10'000u);
  EXPECT_EQ(got.size(), expectedIn);
  double worstPx = 0, worstRange = 0;
  for (const ProjectedPoint& p : got) {
    const Expected& e = expected.at(p.index);
    EXPECT_TRUE(inImage(e, w, h, 0.05)) << p.index;
    worstPx = std::max({worstPx, std::abs(p.u - e.u), std::abs(p.v - e.v)});
    worstRange = std::max(worstRange, std::abs(p.distance - e.range));
    EXPECT_EQ(p.remission, f.points.points[p.index].remission);
  }
  EXPECT_LT(worstPx, 0.01);
  EXPECT_LT(worstRange, 1e-4);  // float storage of metres
}
}  // namespace

TEST(KittiProjection, MatchesP2R0TrOnRealFramesOfEveryDrive) {
  checkKittiFrame("kitti", "000000");
  checkKittiFrame("kitti", "000153");
  checkKittiFrame("kitti_0009", "000000");
  checkKittiFrame("kitti_object_sample", "000001");
}

TEST(KittiProjection, DistanceLayerHoldsTheNearestRangePerCell) {
  const KittiFrame f = readKittiFrame(kData / "kitti", "000042");
  const Calib c = parseCalib(kData / "kitti" / "calib" / "000042.txt");
  const int w = f.image.cols, h = f.image.rows;
  ProjectionConfig cfg;
  cfg.holeFillRadius = 0;
  const LaserLayers layers = rasteriseLaserLayers(projectPoints(f.points, kittiProjection(f.calib, w, h), 0.05), w, h, cfg);
  const cv::Mat& d = layers.distance.data;
  EXPECT_EQ(d.cols, 621);
  EXPECT_EQ(d.rows, 188);
  // Independent z-buffer: per cell, the smallest range of the points that land in it.
  // Points within 1e-3 px of a cell border may fall on either side (float pixel coordinates);
  // the cells next to such a border are left out of the comparison.
  std::map<std::pair<int, int>, std::pair<double, float>> nearest;
  std::set<std::pair<int, int>> ambiguous;
  const auto expected = expectedProjection(f.points, c);
  for (std::size_t i = 0; i < expected.size(); ++i) {
    const Expected& e = expected[i];
    if (!inImage(e, w, h, 0.05)) continue;
    const double cu = e.u * 621.0 / w, cv = e.v * 188.0 / h;
    const std::pair<int, int> cell{static_cast<int>(std::floor(cu)), static_cast<int>(std::floor(cv))};
    const double eps = 1e-3 * 0.5;
    if (std::floor(cu - eps) != std::floor(cu + eps) || std::floor(cv - eps) != std::floor(cv + eps))
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) ambiguous.insert({cell.first + dx, cell.second + dy});
    auto it = nearest.find(cell);
    if (it == nearest.end() || e.range < it->second.first) nearest[cell] = {e.range, f.points.points[i].remission};
  }
  EXPECT_LT(ambiguous.size(), nearest.size() / 50);
  EXPECT_NEAR(static_cast<double>(cv::countNonZero(layers.distance.valid)), static_cast<double>(nearest.size()),
              static_cast<double>(ambiguous.size()));
  int wrong = 0;
  for (const auto& [cell, best] : nearest) {
    if (ambiguous.contains(cell)) continue;
    if (layers.distance.valid.at<std::uint8_t>(cell.second, cell.first) != kMaskMeasured) ++wrong;
    if (std::abs(d.at<float>(cell.second, cell.first) - best.first) > 1e-4) ++wrong;
    if (layers.remission.data.at<float>(cell.second, cell.first) != best.second) ++wrong;
  }
  EXPECT_EQ(wrong, 0);
  // Cells without points are invalid and 0.
  EXPECT_EQ(cv::countNonZero(d), cv::countNonZero(layers.distance.valid));
}

namespace {
PinholeProjection simpleCamera() {
  PinholeProjection p;
  p.K << 100, 0, 50, 0, 100, 40, 0, 0, 1;
  p.width = 100;
  p.height = 80;
  return p;  // camera frame = sweep frame
}
Sweep sweepOf(std::vector<SweepPoint> points) {
  Sweep s;
  s.points = std::move(points);
  return s;
}
}  // namespace

TEST(Projection, DropsPointsBehindTheCameraAndOutsideTheImage) {
  const Sweep s = sweepOf({
      {0, 0, 5, 0.5f, 0},       // centre: u 50, v 40
      {0, 0, -5, 0.5f, 0},      // behind
      {0.1f, 0, -0.01f, 0, 0},  // just behind the image plane
      {3, 0, 5, 0, 0},          // u = 110: right of the image
      {-2.6f, 0, 5, 0, 0},      // u = -2: left
      {0, 2.1f, 5, 0, 0},       // v = 82: below
      {0, 0, 0.01f, 0, 0},      // in front but closer than minDepth
      {2.45f, 1.95f, 5, 2.f, 0},  // u 99, v 79: last pixel; remission clamped to 1
  });
  const auto got = projectPoints(s, simpleCamera(), 0.05);
  ASSERT_EQ(got.size(), 2u);
  EXPECT_EQ(got[0].index, 0u);
  EXPECT_FLOAT_EQ(got[0].u, 50);
  EXPECT_FLOAT_EQ(got[0].v, 40);
  EXPECT_FLOAT_EQ(got[0].distance, 5);
  EXPECT_EQ(got[1].index, 7u);
  EXPECT_NEAR(got[1].u, 99, 1e-4);
  EXPECT_NEAR(got[1].v, 79, 1e-4);
  EXPECT_FLOAT_EQ(got[1].remission, 1.f);
  EXPECT_NEAR(got[1].distance, std::sqrt(2.45 * 2.45 + 1.95 * 1.95 + 25), 1e-5);
}

TEST(Projection, NearestPointOfACellWinsInEitherOrder) {
  // Two points on one ray (same pixel) at 10 m and 4 m, plus a third in another cell.
  const SweepPoint far{0.5f, 0.2f, 10, 0.9f, 0}, nearP{0.2f, 0.08f, 4, 0.1f, 0}, other{-1, -1, 5, 0.3f, 0};
  ProjectionConfig cfg;
  cfg.holeFillRadius = 0;
  for (const auto& pts : {std::vector<SweepPoint>{far, nearP, other}, std::vector<SweepPoint>{nearP, far, other}}) {
    const LaserLayers l = rasteriseLaserLayers(projectPoints(sweepOf(pts), simpleCamera(), 0.05), 100, 80, cfg);
    // u = 55, v = 42 -> cell (27, 21) of the 50 x 40 grid
    EXPECT_NEAR(l.distance.data.at<float>(21, 27), std::sqrt(0.04 + 0.0064 + 16), 1e-5);
    EXPECT_FLOAT_EQ(l.remission.data.at<float>(21, 27), 0.1f);
    EXPECT_EQ(cv::countNonZero(l.distance.valid), 2);
  }
}

TEST(Projection, FillsSmallHolesByInverseSquareWeightsAndLeavesLargeOnes) {
  cv::Mat v(9, 12, CV_32FC1, cv::Scalar(0)), m(9, 12, CV_8UC1, cv::Scalar(0));
  // Row 4: measured at x = 2 (value 2) and x = 5 (value 8); the cells between get filled.
  v.at<float>(4, 2) = 2;
  v.at<float>(4, 5) = 8;
  m.at<std::uint8_t>(4, 2) = m.at<std::uint8_t>(4, 5) = kMaskMeasured;
  cv::Mat v2 = v * 10;
  fillHoles({&v, &v2}, m, 2);
  // x = 3: neighbours at distance 1 (value 2, weight 1) and 2 (value 8, weight 1/4).
  EXPECT_NEAR(v.at<float>(4, 3), (2 * 1.0 + 8 * 0.25) / 1.25, 1e-5);
  EXPECT_NEAR(v2.at<float>(4, 3), 10 * (2 * 1.0 + 8 * 0.25) / 1.25, 1e-4);
  EXPECT_EQ(m.at<std::uint8_t>(4, 3), kMaskFilled);
  // Diagonal neighbour (dx 1, dy 1: weight 1/2) alone.
  EXPECT_NEAR(v.at<float>(5, 1), 2, 1e-6);
  // Measured cells keep their values.
  EXPECT_EQ(v.at<float>(4, 2), 2);
  EXPECT_EQ(m.at<std::uint8_t>(4, 5), kMaskMeasured);
  // Farther than 2 cells from any measurement: still empty and invalid.
  EXPECT_EQ(m.at<std::uint8_t>(4, 8), 0);
  EXPECT_EQ(v.at<float>(4, 8), 0);
  EXPECT_EQ(m.at<std::uint8_t>(7, 2), 0);
  EXPECT_EQ(m.at<std::uint8_t>(6, 2), kMaskFilled);
}

TEST(Projection, LaserLayerSizeFollowsTheScale) {
  EXPECT_EQ(laserLayerSize(1242, 375, 0.5), cv::Size(621, 188));
  EXPECT_EQ(laserLayerSize(640, 480, 0.25), cv::Size(160, 120));
  EXPECT_THROW((void)laserLayerSize(640, 480, 0), std::invalid_argument);
  EXPECT_THROW((void)laserLayerSize(640, 480, 1.5), std::invalid_argument);
}
