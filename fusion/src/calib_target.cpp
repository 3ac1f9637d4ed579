#include "fusedet/fusion/calib_target.h"

#include <Eigen/Eigenvalues>
#include <Eigen/SVD>
#include <cmath>
#include <opencv2/calib3d.hpp>
#include <opencv2/imgproc.hpp>
#include <random>
#include <sstream>
#include <string>

#include "jackknife.h"

namespace fusedet::fusion {
namespace {

Plane oriented(const Eigen::Vector3d& n, double d) {
  return d < 0 ? Plane{-n, -d} : Plane{n, d};
}

// Least-squares plane through points; also the spread of the points within the plane (the
// smaller in-plane standard deviation) so collinear input can be told apart.
Plane fitPlane(const std::vector<Eigen::Vector3d>& pts, double* inPlaneSpread = nullptr) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts) c += p;
  c /= static_cast<double>(pts.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) cov += (p - c) * (p - c).transpose();
  cov /= static_cast<double>(pts.size());
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);  // ascending eigenvalues
  if (inPlaneSpread) *inPlaneSpread = std::sqrt(std::max(0.0, es.eigenvalues()(1)));
  const Eigen::Vector3d n = es.eigenvectors().col(0);
  return oriented(n, n.dot(c));
}

std::string vec(const Eigen::Vector3d& v) {
  std::ostringstream s;
  s.precision(2);
  s << std::fixed << "(" << v.x() << ", " << v.y() << ", " << v.z() << ")";
  return s.str();
}

// Rejects inputs whose board normals leave the transform unconstrained.
void checkPoses(const std::vector<BoardObservation>& boards, const TargetCalibrationOptions& options) {
  if (boards.size() < 3)
    throw CalibrationError("target calibration needs at least 3 board poses, got " + std::to_string(boards.size()));
  Eigen::MatrixXd N(static_cast<Eigen::Index>(boards.size()), 3);
  for (std::size_t i = 0; i < boards.size(); ++i) {
    if (boards[i].laserPoints.size() < options.minPointsPerBoard)
      throw CalibrationError("board pose " + std::to_string(i + 1) + " has only " +
                             std::to_string(boards[i].laserPoints.size()) + " laser points (need at least " +
                             std::to_string(options.minPointsPerBoard) + ")");
    N.row(static_cast<Eigen::Index>(i)) = boards[i].camera.normal.transpose();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(N, Eigen::ComputeFullV);
  const Eigen::Vector3d s = svd.singularValues() / std::sqrt(static_cast<double>(boards.size()));
  if (s(1) < options.minNormalSpread)
    throw CalibrationError("degenerate board poses: all " + std::to_string(boards.size()) +
                           " board planes are (nearly) parallel, so the rotation about their normal and the "
                           "translation within them are not observable; tilt the board differently in each pose");
  if (s(2) < options.minNormalSpread)
    throw CalibrationError("degenerate board poses: all board normals lie (nearly) in one plane, so the translation "
                           "along " + vec(svd.matrixV().col(2)) + " (camera frame) is not observable; tilt the "
                           "board about a second axis as well");
}

struct Solution {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  double rms = 0;
};

Solution solve(const std::vector<BoardObservation>& boards, const TargetCalibrationOptions& options) {
  checkPoses(boards, options);
  // Laser planes; each must be a plane, not a line of points.
  std::vector<Plane> laser;
  for (std::size_t i = 0; i < boards.size(); ++i) {
    double spread = 0;
    laser.push_back(fitPlane(boards[i].laserPoints, &spread));
    if (spread < 0.02)
      throw CalibrationError("board pose " + std::to_string(i + 1) + ": the laser points are (nearly) collinear (" +
                             std::to_string(spread) + " m across), they do not fix the board plane");
  }
  // Rotation: R n_laser = n_camera for every board (orthogonal Procrustes / Kabsch).
  Eigen::Matrix3d H = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < boards.size(); ++i) H += laser[i].normal * boards[i].camera.normal.transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  // Translation: n_camera . t = d_camera - d_laser (a laser plane point p has n_laser . p = d_laser).
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < boards.size(); ++i) {
    const Eigen::Vector3d& n = boards[i].camera.normal;
    A += n * n.transpose();
    b += n * (boards[i].camera.distance - laser[i].distance);
  }
  Eigen::Vector3d t = A.ldlt().solve(b);

  // Gauss-Newton on r = n . (R p + t) - d over every laser board point, each board weighted
  // equally (1 / its point count) so that a close board with many points does not dominate.
  double rms = 0;
  for (int it = 0; it < options.iterations; ++it) {
    Eigen::Matrix<double, 6, 6> JtJ = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Jtr = Eigen::Matrix<double, 6, 1>::Zero();
    double sse = 0;
    std::size_t count = 0;
    for (const BoardObservation& bo : boards) {
      const double w = 1.0 / static_cast<double>(bo.laserPoints.size());
      for (const Eigen::Vector3d& p : bo.laserPoints) {
        const Eigen::Vector3d q = R * p;
        const double r = bo.camera.normal.dot(q + t) - bo.camera.distance;
        Eigen::Matrix<double, 6, 1> j;
        j << q.cross(bo.camera.normal), bo.camera.normal;  // d r / d(rotation vector, translation)
        JtJ += w * j * j.transpose();
        Jtr += w * j * r;
        sse += r * r;
        ++count;
      }
    }
    rms = std::sqrt(sse / static_cast<double>(count));
    const Eigen::Matrix<double, 6, 1> step = -JtJ.ldlt().solve(Jtr);
    const Eigen::Vector3d w = step.head<3>();
    if (w.norm() > 0) R = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix() * R;
    t += step.tail<3>();
    if (step.head<3>().norm() < 1e-10 && step.tail<3>().norm() < 1e-10) break;
  }
  Solution s;
  s.T.linear() = R;
  s.T.translation() = t;
  s.rms = rms;
  return s;
}

}  // namespace

std::vector<cv::Point2f> detectCheckerboard(const cv::Mat& image, const Checkerboard& board) {
  if (image.empty()) throw CalibrationError("checkerboard: empty image");
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  std::vector<cv::Point2f> corners;
  if (!cv::findChessboardCorners(grey, board.innerCorners, corners,
                                 cv::CALIB_CB_ADAPTIVE_THRESH | cv::CALIB_CB_NORMALIZE_IMAGE))
    throw CalibrationError("no " + std::to_string(board.innerCorners.width) + " x " +
                           std::to_string(board.innerCorners.height) + " checkerboard found in the image");
  cv::cornerSubPix(grey, corners, {5, 5}, {-1, -1},
                   cv::TermCriteria(cv::TermCriteria::EPS + cv::TermCriteria::COUNT, 50, 1e-3));
  return corners;
}

Plane cameraBoardPlane(const std::vector<cv::Point2f>& corners, const Checkerboard& board, const CameraModel& camera) {
  const std::size_t expected = static_cast<std::size_t>(board.innerCorners.area());
  if (corners.size() != expected)
    throw CalibrationError("checkerboard: " + std::to_string(corners.size()) + " corners, expected " +
                           std::to_string(expected));
  std::vector<cv::Point3f> object;
  for (int r = 0; r < board.innerCorners.height; ++r)
    for (int c = 0; c < board.innerCorners.width; ++c)
      object.emplace_back(static_cast<float>(c * board.squareSize), static_cast<float>(r * board.squareSize), 0.f);
  cv::Mat K(3, 3, CV_64F);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) K.at<double>(r, c) = camera.K(r, c);
  cv::Mat dist(camera.distortion, true);
  cv::Mat rvec, tvec;
  if (!cv::solvePnP(object, corners, K, dist, rvec, tvec, false, cv::SOLVEPNP_ITERATIVE))
    throw CalibrationError("checkerboard: solvePnP found no board pose");
  cv::Mat Rcv;
  cv::Rodrigues(rvec, Rcv);
  const Eigen::Vector3d n(Rcv.at<double>(0, 2), Rcv.at<double>(1, 2), Rcv.at<double>(2, 2));
  const Eigen::Vector3d t(tvec.at<double>(0), tvec.at<double>(1), tvec.at<double>(2));
  return oriented(n, n.dot(t));
}

LaserPlane fitLaserBoardPlane(const std::vector<Eigen::Vector3d>& points, const LaserPlaneOptions& options) {
  if (points.size() < options.minInliers)
    throw CalibrationError("laser board plane: only " + std::to_string(points.size()) + " points (need at least " +
                           std::to_string(options.minInliers) + ")");
  std::mt19937 rng(options.seed);
  std::uniform_int_distribution<std::size_t> pick(0, points.size() - 1);
  auto inliersOf = [&](const Plane& pl) {
    std::vector<Eigen::Vector3d> in;
    for (const auto& p : points)
      if (std::abs(pl.normal.dot(p) - pl.distance) <= options.inlierDistance) in.push_back(p);
    return in;
  };
  std::size_t bestCount = 0;
  Plane best;
  for (int it = 0; it < options.iterations; ++it) {
    const Eigen::Vector3d &a = points[pick(rng)], &b = points[pick(rng)], &c = points[pick(rng)];
    const Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-9) continue;
    const Plane pl = oriented(n.normalized(), n.normalized().dot(a));
    std::size_t count = 0;
    for (const auto& p : points) count += std::abs(pl.normal.dot(p) - pl.distance) <= options.inlierDistance;
    if (count > bestCount) {
      bestCount = count;
      best = pl;
    }
  }
  if (bestCount < options.minInliers)
    throw CalibrationError("laser board plane: the best plane has only " + std::to_string(bestCount) +
                           " inliers (need at least " + std::to_string(options.minInliers) + ")");
  LaserPlane out;
  out.plane = fitPlane(inliersOf(best));
  out.inliers = inliersOf(out.plane);  // once more with the refined plane
  if (out.inliers.size() < options.minInliers)
    throw CalibrationError("laser board plane: only " + std::to_string(out.inliers.size()) + " inliers after refinement");
  out.plane = fitPlane(out.inliers);
  double sse = 0;
  for (const auto& p : out.inliers) sse += std::pow(out.plane.normal.dot(p) - out.plane.distance, 2);
  out.rms = std::sqrt(sse / static_cast<double>(out.inliers.size()));
  return out;
}

TargetCalibration calibrateFromBoards(const std::vector<BoardObservation>& boards, const TargetCalibrationOptions& options) {
  const Solution s = solve(boards, options);
  TargetCalibration result;
  result.laserToCamera = s.T;
  result.rmsDistance = s.rms;
  if (boards.size() < 4) return result;
  // Jackknife over boards: the spread of the leave-one-out solutions.
  std::vector<Eigen::Isometry3d> loo;
  for (std::size_t leave = 0; leave < boards.size(); ++leave) {
    std::vector<BoardObservation> rest;
    for (std::size_t i = 0; i < boards.size(); ++i)
      if (i != leave) rest.push_back(boards[i]);
    try {
      loo.push_back(solve(rest, options).T);
    } catch (const CalibrationError&) {
      return result;  // a subset is degenerate: no spread to measure
    }
  }
  const detail::PoseSpread spread = detail::jackknifeSpread(loo, s.T);
  result.rotationStdDeg = spread.rotationStdDeg;
  result.translationStd = spread.translationStd;
  return result;
}

}  // namespace fusedet::fusion
