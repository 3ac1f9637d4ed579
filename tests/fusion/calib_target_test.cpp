// Target-based calibration against a simulated rig: board corners projected with our own pinhole
// code and noise, laser points ray-cast onto the board with range noise and clutter. The simulator
// shares no code with the calibration (it only calls OpenCV to render the board image).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <random>

#include "fusedet/fusion/calib_target.h"
#include "fusedet/fusion/calib_targetless.h"

namespace fusedet::fusion {
namespace {

constexpr double kPi = 3.14159265358979323846;

Eigen::Matrix3d rotXYZ(double xDeg, double yDeg, double zDeg) {
  return (Eigen::AngleAxisd(zDeg * kPi / 180, Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(yDeg * kPi / 180, Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(xDeg * kPi / 180, Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

struct Rig {
  CameraModel camera;
  Eigen::Isometry3d laserToCamera = Eigen::Isometry3d::Identity();
  Checkerboard board{{7, 5}, 0.1};
  Rig() {
    camera.width = 1280;
    camera.height = 720;
    camera.K << 700, 0, 640, 0, 700, 360, 0, 0, 1;
    // A Velodyne-like laser (x ahead, y left, z up) beside the camera, slightly rotated.
    Eigen::Matrix3d base;
    base << 0, -1, 0, 0, 0, -1, 1, 0, 0;
    laserToCamera.linear() = rotXYZ(1.2, -0.7, 2.1) * base;
    laserToCamera.translation() = Eigen::Vector3d(0.08, -0.21, -0.05);
  }
};

// Board pose in the camera frame: board x along the corner rows, y down the columns, z its normal.
Eigen::Isometry3d boardPose(double tiltXDeg, double tiltYDeg, const Eigen::Vector3d& centre, const Checkerboard& b) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotXYZ(tiltXDeg, tiltYDeg, 0);
  // Centre the corner grid on `centre`.
  const Eigen::Vector3d half((b.innerCorners.width - 1) * b.squareSize / 2, (b.innerCorners.height - 1) * b.squareSize / 2, 0);
  T.translation() = centre - T.linear() * half;
  return T;
}

std::vector<cv::Point2f> projectCorners(const Rig& rig, const Eigen::Isometry3d& pose, double noisePx, std::mt19937& rng) {
  std::normal_distribution<double> noise(0, noisePx);
  std::vector<cv::Point2f> out;
  for (int r = 0; r < rig.board.innerCorners.height; ++r)
    for (int c = 0; c < rig.board.innerCorners.width; ++c) {
      const Eigen::Vector3d p = pose * Eigen::Vector3d(c * rig.board.squareSize, r * rig.board.squareSize, 0);
      const Eigen::Vector3d px = rig.camera.K * p / p.z();
      out.emplace_back(static_cast<float>(px.x() + noise(rng)), static_cast<float>(px.y() + noise(rng)));
    }
  return out;
}

// Rays of a 3D scanner (laser frame) hitting the board (with its white border of one square),
// range noise sigma `noiseM`, plus `clutter` uniform points in a box around the board.
std::vector<Eigen::Vector3d> scanBoard(const Rig& rig, const Eigen::Isometry3d& pose, double noiseM, int clutter,
                                       std::mt19937& rng) {
  const Eigen::Isometry3d boardToLaser = rig.laserToCamera.inverse() * pose;
  const Eigen::Vector3d n = boardToLaser.linear().col(2), o = boardToLaser.translation();
  const double s = rig.board.squareSize;
  const double xmin = -1.5 * s, xmax = (rig.board.innerCorners.width + 0.5) * s;
  const double ymin = -1.5 * s, ymax = (rig.board.innerCorners.height + 0.5) * s;
  std::normal_distribution<double> noise(0, noiseM);
  std::vector<Eigen::Vector3d> pts;
  for (double el = -20; el <= 20; el += 0.4)
    for (double az = -60; az <= 60; az += 0.2) {
      const Eigen::Vector3d d(std::cos(el * kPi / 180) * std::cos(az * kPi / 180),
                              std::cos(el * kPi / 180) * std::sin(az * kPi / 180), std::sin(el * kPi / 180));
      const double denom = n.dot(d);
      if (std::abs(denom) < 1e-6) continue;
      const double range = n.dot(o) / denom;
      if (range <= 0) continue;
      const Eigen::Vector3d local = boardToLaser.inverse() * (range * d);
      if (local.x() < xmin || local.x() > xmax || local.y() < ymin || local.y() > ymax) continue;
      pts.push_back((range + noise(rng)) * d);
    }
  Eigen::Vector3d lo = pts.front(), hi = pts.front();
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < clutter; ++i) {
    const Eigen::Vector3d a(u(rng), u(rng), u(rng));
    pts.push_back(lo.array() - 0.3 + a.array() * (hi - lo).array() + 0.6 * a.array());
  }
  return pts;
}

std::vector<BoardObservation> simulate(const Rig& rig, const std::vector<Eigen::Isometry3d>& poses, std::mt19937& rng,
                                       double cornerNoisePx = 0.3, double rangeNoiseM = 0.01, int clutter = 150) {
  std::vector<BoardObservation> obs;
  for (const auto& pose : poses) {
    BoardObservation o;
    o.camera = cameraBoardPlane(projectCorners(rig, pose, cornerNoisePx, rng), rig.board, rig.camera);
    const std::vector<Eigen::Vector3d> scan = scanBoard(rig, pose, rangeNoiseM, clutter, rng);
    o.laserPoints = fitLaserBoardPlane(scan).inliers;
    obs.push_back(o);
  }
  return obs;
}

// A calibration session: 12 poses, tilted up to 35 deg about both axes, 2 to 4 m away.
std::vector<Eigen::Isometry3d> goodPoses(const Checkerboard& b) {
  std::vector<Eigen::Isometry3d> poses;
  const double tilts[12][2] = {{25, 0},   {-20, 20}, {0, -30}, {15, 25},  {-25, -15}, {30, 10},
                               {-10, 35}, {10, -20}, {-30, 0}, {20, -35}, {0, 25},    {-15, -30}};
  for (int i = 0; i < 12; ++i)
    poses.push_back(boardPose(tilts[i][0], tilts[i][1], {0.5 * std::sin(i), 0.3 * std::cos(1.7 * i), 2.0 + 0.18 * i}, b));
  return poses;
}

TEST(TargetCalibration, RecoversTheTransformFromNoisyBoards) {
  const Rig rig;
  std::mt19937 rng(7);
  const auto obs = simulate(rig, goodPoses(rig.board), rng);
  const TargetCalibration c = calibrateFromBoards(obs);
  const double rotDeg = rotationErrorDeg(c.laserToCamera, rig.laserToCamera);
  const double transM = translationError(c.laserToCamera, rig.laserToCamera);
  std::printf("target-based: rotation error %.4f deg, translation error %.4f m, rms %.4f m, "
              "sigma rot [%.3f %.3f %.3f] deg, t [%.4f %.4f %.4f] m\n",
              rotDeg, transM, c.rmsDistance, c.rotationStdDeg.x(), c.rotationStdDeg.y(), c.rotationStdDeg.z(),
              c.translationStd.x(), c.translationStd.y(), c.translationStd.z());
  EXPECT_LT(rotDeg, 0.2);
  EXPECT_LT(transM, 0.01);
  EXPECT_LT(c.rmsDistance, 0.02);  // range noise 1 cm
  EXPECT_TRUE(std::isfinite(c.translationStd.x()));
  // The start is far from identity, so agreement is not an accident of the initial guess.
  EXPECT_GT(rotationErrorDeg(Eigen::Isometry3d::Identity(), rig.laserToCamera), 90.0);
}

TEST(TargetCalibration, NoiseFreeBoardsGiveTheExactTransform) {
  const Rig rig;
  std::mt19937 rng(3);
  const auto obs = simulate(rig, goodPoses(rig.board), rng, 0.0, 0.0, 0);
  const TargetCalibration c = calibrateFromBoards(obs);
  EXPECT_LT(rotationErrorDeg(c.laserToCamera, rig.laserToCamera), 1e-3);
  EXPECT_LT(translationError(c.laserToCamera, rig.laserToCamera), 1e-4);
}

TEST(TargetCalibration, RejectsParallelBoards) {
  const Rig rig;
  std::mt19937 rng(1);
  const auto obs = simulate(rig, {boardPose(10, 5, {0, 0, 2.5}, rig.board), boardPose(10, 5, {-0.5, 0.1, 3.0}, rig.board),
                                  boardPose(10, 5, {0.5, 0.2, 3.5}, rig.board), boardPose(10, 5, {0.2, -0.2, 2.0}, rig.board)},
                            rng);
  try {
    (void)calibrateFromBoards(obs);
    FAIL() << "parallel boards accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("parallel"), std::string::npos) << e.what();
  }
}

TEST(TargetCalibration, RejectsBoardsTiltedAboutOneAxisOnly) {
  const Rig rig;
  std::mt19937 rng(2);
  const auto obs = simulate(rig, {boardPose(-30, 0, {0, 0, 2.5}, rig.board), boardPose(0, 0, {-0.5, 0.1, 3.0}, rig.board),
                                  boardPose(30, 0, {0.5, 0.2, 3.5}, rig.board)},
                            rng);
  try {
    (void)calibrateFromBoards(obs);
    FAIL() << "boards tilted about one axis accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("not observable"), std::string::npos) << e.what();
  }
}

TEST(TargetCalibration, RejectsTooFewPosesAndPoints) {
  const Rig rig;
  std::mt19937 rng(4);
  auto obs = simulate(rig, goodPoses(rig.board), rng);
  std::vector<BoardObservation> two(obs.begin(), obs.begin() + 2);
  try {
    (void)calibrateFromBoards(two);
    FAIL() << "two poses accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("at least 3 board poses, got 2"), std::string::npos) << e.what();
  }
  obs[1].laserPoints.resize(12);
  try {
    (void)calibrateFromBoards(obs);
    FAIL() << "a board with 12 points accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("board pose 2 has only 12 laser points"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)fitLaserBoardPlane(std::vector<Eigen::Vector3d>(5, Eigen::Vector3d(1, 2, 3))), CalibrationError);
  // A single scan line across each board (a 2D scanner) fixes no plane.
  for (auto& o : obs) {
    std::vector<Eigen::Vector3d> line;
    for (int i = 0; i < 40; ++i) line.push_back(o.laserPoints.front() + 0.01 * i * Eigen::Vector3d(0, 1, 0));
    o.laserPoints = line;
  }
  try {
    (void)calibrateFromBoards(obs);
    FAIL() << "collinear laser points accepted";
  } catch (const CalibrationError& e) {
    EXPECT_NE(std::string(e.what()).find("collinear"), std::string::npos) << e.what();
  }
}

TEST(TargetCalibration, RansacIgnoresClutter) {
  const Rig rig;
  std::mt19937 rng(5);
  const Eigen::Isometry3d pose = boardPose(20, 10, {0, 0, 3}, rig.board);
  const auto scan = scanBoard(rig, pose, 0.005, 400, rng);
  const LaserPlane fit = fitLaserBoardPlane(scan);
  const Eigen::Isometry3d boardToLaser = rig.laserToCamera.inverse() * pose;
  const Eigen::Vector3d n = boardToLaser.linear().col(2);
  EXPECT_GT(std::abs(fit.plane.normal.dot(n)), std::cos(0.5 * kPi / 180));
  EXPECT_NEAR(fit.plane.distance, std::abs(n.dot(boardToLaser.translation())), 0.005);
  EXPECT_LT(fit.inliers.size(), scan.size());
  EXPECT_LT(fit.rms, 0.01);
}

// Renders the board (white border of one square) into an image by a homography from our own
// pose and K, then detects it with OpenCV: the plane from the detected corners matches the pose.
TEST(TargetCalibration, DetectsARenderedBoard) {
  const Rig rig;
  const Eigen::Isometry3d pose = boardPose(20, -25, {0.2, 0.1, 2.0}, rig.board);
  const int px = 60;  // texture pixels per square
  const int cols = rig.board.innerCorners.width + 1, rows = rig.board.innerCorners.height + 1;
  cv::Mat texture((rows + 2) * px, (cols + 2) * px, CV_8UC1, cv::Scalar(255));
  for (int r = 0; r < rows; ++r)
    for (int c = 0; c < cols; ++c)
      if ((r + c) % 2 == 0) texture(cv::Rect((c + 1) * px, (r + 1) * px, px, px)).setTo(0);
  // Texture pixel (i, j) -> board metres: the first inner corner is at texture (2px, 2px).
  const double m = rig.board.squareSize / px;
  Eigen::Matrix3d S;
  S << m, 0, -2 * px * m, 0, m, -2 * px * m, 0, 0, 1;
  Eigen::Matrix3d Rt;
  Rt << pose.linear().col(0), pose.linear().col(1), pose.translation();
  const Eigen::Matrix3d H = rig.camera.K * Rt * S;
  cv::Mat Hcv(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Hcv.at<double>(r, c) = H(r, c);
  cv::Mat image;
  cv::warpPerspective(texture, image, Hcv, {rig.camera.width, rig.camera.height}, cv::INTER_LINEAR,
                      cv::BORDER_CONSTANT, cv::Scalar(128));
  const Plane plane = cameraBoardPlane(detectCheckerboard(image, rig.board), rig.board, rig.camera);
  const Eigen::Vector3d n = pose.linear().col(2);
  EXPECT_GT(std::abs(plane.normal.dot(n)), std::cos(0.5 * kPi / 180));
  EXPECT_NEAR(plane.distance, std::abs(n.dot(pose.translation())), 0.01);
  const cv::Mat blank(rig.camera.height, rig.camera.width, CV_8UC1, cv::Scalar(128));
  EXPECT_THROW((void)detectCheckerboard(blank, rig.board), CalibrationError);
}

}  // namespace
}  // namespace fusedet::fusion
