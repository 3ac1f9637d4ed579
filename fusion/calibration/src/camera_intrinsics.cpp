// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/camera_intrinsics.h"

#include <Eigen/Dense>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fusedet::fusion {
namespace {

constexpr int kIntrinsics = 9;  // fx fy cx cy k1 k2 p1 p2 k3
constexpr int kPose = 6;        // rotation vector, translation

// Board plane (x, y) -> image pixels, by the normalised direct linear transform: points centred
// and scaled to unit spread first, so the 9 unknowns are of one magnitude.
Eigen::Matrix3d homography(const std::vector<cv::Point3f>& plane, const std::vector<cv::Point2f>& image) {
  auto normaliser = [](const std::vector<Eigen::Vector2d>& p) {
    Eigen::Vector2d mean = Eigen::Vector2d::Zero();
    for (const auto& q : p) mean += q;
    mean /= static_cast<double>(p.size());
    double spread = 0;
    for (const auto& q : p) spread += (q - mean).norm();
    const double s = std::sqrt(2.0) * static_cast<double>(p.size()) / spread;
    Eigen::Matrix3d T;
    T << s, 0, -s * mean.x(), 0, s, -s * mean.y(), 0, 0, 1;
    return T;
  };
  std::vector<Eigen::Vector2d> a, b;
  for (std::size_t i = 0; i < plane.size(); ++i) {
    a.emplace_back(plane[i].x, plane[i].y);
    b.emplace_back(image[i].x, image[i].y);
  }
  const Eigen::Matrix3d Ta = normaliser(a), Tb = normaliser(b);
  Eigen::MatrixXd M(2 * a.size(), 9);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Eigen::Vector3d p = Ta * a[i].homogeneous(), q = Tb * b[i].homogeneous();
    const auto r = static_cast<Eigen::Index>(2 * i);
    M.row(r) << p.x(), p.y(), 1, 0, 0, 0, -q.x() * p.x(), -q.x() * p.y(), -q.x();
    M.row(r + 1) << 0, 0, 0, p.x(), p.y(), 1, -q.y() * p.x(), -q.y() * p.y(), -q.y();
  }
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(M, Eigen::ComputeFullV);
  const Eigen::Matrix<double, 9, 1> h = svd.matrixV().col(8);
  Eigen::Matrix3d Hn;
  Hn << h(0), h(1), h(2), h(3), h(4), h(5), h(6), h(7), h(8);
  return Tb.inverse() * Hn * Ta;
}

// Zhang's closed form with zero skew: each homography gives two linear constraints on
// B = K^-T K^-1 (h1' B h2 = 0, h1' B h1 = h2' B h2); B's null vector gives K.
Eigen::Matrix3d closedFormK(const std::vector<Eigen::Matrix3d>& H) {
  auto v = [](const Eigen::Matrix3d& h, int i, int j) {
    Eigen::Matrix<double, 1, 6> r;
    r << h(0, i) * h(0, j), h(0, i) * h(1, j) + h(1, i) * h(0, j), h(1, i) * h(1, j),
        h(2, i) * h(0, j) + h(0, i) * h(2, j), h(2, i) * h(1, j) + h(1, i) * h(2, j), h(2, i) * h(2, j);
    return r;
  };
  Eigen::MatrixXd V(2 * H.size() + 1, 6);
  for (std::size_t k = 0; k < H.size(); ++k) {
    const auto r = static_cast<Eigen::Index>(2 * k);
    V.row(r) = v(H[k], 0, 1);
    V.row(r + 1) = v(H[k], 0, 0) - v(H[k], 1, 1);
  }
  V.row(V.rows() - 1) << 0, 1, 0, 0, 0, 0;  // B12 = 0: no skew
  const Eigen::JacobiSVD<Eigen::MatrixXd> svd(V, Eigen::ComputeFullV);
  Eigen::Matrix<double, 6, 1> b = svd.matrixV().col(5);
  if (b(0) < 0) b = -b;  // B is positive definite up to the null vector's sign
  const double B11 = b(0), B12 = b(1), B22 = b(2), B13 = b(3), B23 = b(4), B33 = b(5);
  const double d = B11 * B22 - B12 * B12;
  const double v0 = (B12 * B13 - B11 * B23) / d;
  const double lambda = B33 - (B13 * B13 + v0 * (B12 * B13 - B11 * B23)) / B11;
  const double fx = std::sqrt(lambda / B11), fy = std::sqrt(lambda * B11 / d);
  const double u0 = -B13 * fx * fx / lambda;
  if (!std::isfinite(fx) || !std::isfinite(fy) || fx <= 0 || fy <= 0)
    throw std::invalid_argument(
        "calibrate-camera: the views do not determine the focal length (the board must be seen at 3 or more different "
        "tilts, not only turned in its plane)");
  Eigen::Matrix3d K;
  K << fx, 0, u0, 0, fy, v0, 0, 0, 1;
  return K;
}

// The board's pose from its homography and K: the columns of K^-1 H are r1, r2, t up to scale.
Eigen::Isometry3d poseFromHomography(const Eigen::Matrix3d& K, const Eigen::Matrix3d& H) {
  Eigen::Matrix3d A = K.inverse() * H;
  double s = 1.0 / A.col(0).norm();
  if (A(2, 2) * s < 0) s = -s;  // the board is in front of the camera
  Eigen::Matrix3d R;
  R.col(0) = s * A.col(0);
  R.col(1) = s * A.col(1);
  R.col(2) = R.col(0).cross(R.col(1));
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(R, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * svd.matrixV().transpose();
  T.translation() = s * A.col(2);
  return T;
}

Eigen::Vector3d rotationVector(const Eigen::Matrix3d& R) {
  const Eigen::AngleAxisd aa(R);
  return aa.axis() * aa.angle();
}

Eigen::Matrix3d rotationFromVector(const Eigen::Vector3d& r) {
  const double angle = r.norm();
  if (angle < 1e-15) return Eigen::Matrix3d::Identity();
  return Eigen::AngleAxisd(angle, r / angle).toRotationMatrix();
}

CameraModel cameraFrom(const Eigen::VectorXd& p, cv::Size size) {
  CameraModel c;
  c.width = size.width;
  c.height = size.height;
  c.K << p(0), 0, p(2), 0, p(1), p(3), 0, 0, 1;
  c.distortion.assign(p.data() + 4, p.data() + kIntrinsics);
  return c;
}

// Residuals (pixels, x then y per corner) of the views selected: every view when `only` < 0.
void residuals(const Eigen::VectorXd& p, const std::vector<std::vector<cv::Point2f>>& views,
               const std::vector<cv::Point3f>& board, cv::Size size, int only, Eigen::VectorXd& out) {
  const CameraModel camera = cameraFrom(p, size);
  for (std::size_t v = 0; v < views.size(); ++v) {
    if (only >= 0 && static_cast<std::size_t>(only) != v) continue;
    const Eigen::Index at = kIntrinsics + kPose * static_cast<Eigen::Index>(v);
    const Eigen::Matrix3d R = rotationFromVector(p.segment<3>(at));
    const Eigen::Vector3d t = p.segment<3>(at + 3);
    for (std::size_t i = 0; i < board.size(); ++i) {
      const Eigen::Vector2d uv = projectPoint(camera, R * Eigen::Vector3d(board[i].x, board[i].y, board[i].z) + t);
      const auto r = static_cast<Eigen::Index>(2 * (v * board.size() + i));
      out(r) = uv.x() - views[v][i].x;
      out(r + 1) = uv.y() - views[v][i].y;
    }
  }
}

// Central-difference Jacobian; a pose parameter moves only its own view's residuals.
Eigen::MatrixXd jacobian(const Eigen::VectorXd& p, const std::vector<std::vector<cv::Point2f>>& views,
                         const std::vector<cv::Point3f>& board, cv::Size size, Eigen::Index residualCount) {
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(residualCount, p.size());
  Eigen::VectorXd plus(residualCount), minus(residualCount);
  for (Eigen::Index k = 0; k < p.size(); ++k) {
    const int view = k < kIntrinsics ? -1 : static_cast<int>((k - kIntrinsics) / kPose);
    const double h = 1e-6 * std::max(1.0, std::abs(p(k)));
    Eigen::VectorXd q = p;
    q(k) = p(k) + h;
    residuals(q, views, board, size, view, plus);
    q(k) = p(k) - h;
    residuals(q, views, board, size, view, minus);
    const Eigen::Index first = view < 0 ? 0 : static_cast<Eigen::Index>(2 * board.size()) * view;
    const Eigen::Index count = view < 0 ? residualCount : static_cast<Eigen::Index>(2 * board.size());
    J.col(k).segment(first, count) = (plus.segment(first, count) - minus.segment(first, count)) / (2 * h);
  }
  return J;
}

}  // namespace

Eigen::Vector2d projectPoint(const CameraModel& camera, const Eigen::Vector3d& X) {
  const double x = X.x() / X.z(), y = X.y() / X.z();
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  const std::vector<double>& d = camera.distortion;
  if (!d.empty()) {
    if (d.size() != 4 && d.size() != 5)
      throw std::invalid_argument("projectPoint: " + std::to_string(d.size()) + " distortion coefficients (4 or 5 expected)");
    k1 = d[0], k2 = d[1], p1 = d[2], p2 = d[3], k3 = d.size() > 4 ? d[4] : 0.0;
  }
  const double r2 = x * x + y * y;
  const double radial = 1 + r2 * (k1 + r2 * (k2 + r2 * k3));
  const double xd = x * radial + 2 * p1 * x * y + p2 * (r2 + 2 * x * x);
  const double yd = y * radial + p1 * (r2 + 2 * y * y) + 2 * p2 * x * y;
  return {camera.K(0, 0) * xd + camera.K(0, 2), camera.K(1, 1) * yd + camera.K(1, 2)};
}

IntrinsicsResult calibrateIntrinsics(const std::vector<std::vector<cv::Point2f>>& views, const BoardSpec& board,
                                     cv::Size imageSize) {
  if (views.size() < 3)
    throw std::invalid_argument("calibrate-camera: " + std::to_string(views.size()) +
                                " views with the whole board; 3 or more are needed (10-20 at different tilts are usual)");
  const std::vector<cv::Point3f> points = boardPoints(board);
  for (const auto& v : views)
    if (v.size() != points.size())
      throw std::invalid_argument("calibrate-camera: a view has " + std::to_string(v.size()) + " corners, the board " +
                                  std::to_string(points.size()));
  std::vector<Eigen::Matrix3d> H;
  for (const auto& v : views) H.push_back(homography(points, v));
  const Eigen::Matrix3d K = closedFormK(H);

  const auto n = static_cast<Eigen::Index>(views.size());
  Eigen::VectorXd p(kIntrinsics + kPose * n);
  p.head<kIntrinsics>() << K(0, 0), K(1, 1), K(0, 2), K(1, 2), 0, 0, 0, 0, 0;
  for (Eigen::Index v = 0; v < n; ++v) {
    const Eigen::Isometry3d T = poseFromHomography(K, H[static_cast<std::size_t>(v)]);
    p.segment<3>(kIntrinsics + kPose * v) = rotationVector(T.linear());
    p.segment<3>(kIntrinsics + kPose * v + 3) = T.translation();
  }

  // Levenberg-Marquardt with Marquardt's scaling (damping in proportion to J'J's diagonal): the
  // parameters differ by orders of magnitude (pixels, coefficients, radians, metres).
  const Eigen::Index m = 2 * static_cast<Eigen::Index>(points.size()) * n;
  Eigen::VectorXd r(m), trial(m);
  residuals(p, views, points, imageSize, -1, r);
  double cost = r.squaredNorm(), mu = 1e-3;
  IntrinsicsResult out;
  Eigen::MatrixXd J;
  for (out.iterations = 0; out.iterations < 200; ++out.iterations) {
    J = jacobian(p, views, points, imageSize, m);
    const Eigen::MatrixXd JtJ = J.transpose() * J;
    const Eigen::VectorXd g = J.transpose() * r;
    bool improved = false;
    double gain = 0;
    while (mu < 1e12) {
      Eigen::MatrixXd A = JtJ;
      A.diagonal() += mu * JtJ.diagonal();
      const Eigen::VectorXd step = A.ldlt().solve(-g);
      const Eigen::VectorXd q = p + step;
      residuals(q, views, points, imageSize, -1, trial);
      const double c = trial.squaredNorm();
      if (std::isfinite(c) && c < cost) {
        gain = (cost - c) / cost;
        p = q, r = trial, cost = c, mu = std::max(mu / 10, 1e-12), improved = true;
        break;
      }
      mu *= 10;
    }
    if (!improved || gain < 1e-12) break;
  }
  out.camera = cameraFrom(p, imageSize);
  out.rmsPx = std::sqrt(cost / static_cast<double>(m / 2));
  const auto perView = static_cast<Eigen::Index>(2 * points.size());
  for (Eigen::Index v = 0; v < n; ++v) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = rotationFromVector(p.segment<3>(kIntrinsics + kPose * v));
    T.translation() = p.segment<3>(kIntrinsics + kPose * v + 3);
    out.boardToCamera.push_back(T);
    out.viewRmsPx.push_back(std::sqrt(r.segment(perView * v, perView).squaredNorm() / static_cast<double>(points.size())));
  }
  J = jacobian(p, views, points, imageSize, m);
  const Eigen::MatrixXd covariance =
      (J.transpose() * J).ldlt().solve(Eigen::MatrixXd::Identity(p.size(), p.size())) * (cost / static_cast<double>(m - p.size()));
  out.sigma = covariance.diagonal().head<kIntrinsics>().cwiseSqrt();
  return out;
}

}  // namespace fusedet::fusion
