// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/kalman.h"

#include <Eigen/Cholesky>
#include <stdexcept>

namespace fusedet::tracking {

ConstantVelocityKalman::ConstantVelocityKalman(const Eigen::Vector3d& position, const KalmanNoise& noise) : noise_(noise) {
  x_.head<3>() = position;
  x_.tail<3>().setZero();
  P_.setZero();
  P_.diagonal().head<3>().setConstant(noise.measurementSigma * noise.measurementSigma);
  P_.diagonal().tail<3>().setConstant(noise.initialVelocitySigma * noise.initialVelocitySigma);
}

void ConstantVelocityKalman::predict(double dt) {
  if (!(dt >= 0)) throw std::invalid_argument("ConstantVelocityKalman::predict: negative or NaN time step");
  if (dt == 0) return;
  // F = [I dt*I; 0 I], written out block by block (F P F' without the 6x6 products).
  x_.head<3>() += dt * x_.tail<3>();
  const Eigen::Matrix3d Ppp = P_.topLeftCorner<3, 3>(), Ppv = P_.topRightCorner<3, 3>(),
                        Pvv = P_.bottomRightCorner<3, 3>();
  const Eigen::Matrix3d newPpv = Ppv + dt * Pvv;
  P_.topLeftCorner<3, 3>() = Ppp + dt * (Ppv + Ppv.transpose()) + dt * dt * Pvv;
  P_.topRightCorner<3, 3>() = newPpv;
  P_.bottomLeftCorner<3, 3>() = newPpv.transpose();
  const double a2 = noise_.accelerationSigma * noise_.accelerationSigma;
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  P_.topLeftCorner<3, 3>() += a2 * dt * dt * dt * dt / 4 * I;
  P_.topRightCorner<3, 3>() += a2 * dt * dt * dt / 2 * I;
  P_.bottomLeftCorner<3, 3>() += a2 * dt * dt * dt / 2 * I;
  P_.bottomRightCorner<3, 3>() += a2 * dt * dt * I;
}

Eigen::Matrix3d ConstantVelocityKalman::innovationCovariance() const {
  return P_.topLeftCorner<3, 3>() +
         noise_.measurementSigma * noise_.measurementSigma * Eigen::Matrix3d::Identity();
}

void ConstantVelocityKalman::update(const Eigen::Vector3d& measured) {
  const Eigen::Vector3d y = measured - position();
  const Eigen::LLT<Eigen::Matrix3d> S(innovationCovariance());
  // K = P H' S^-1 = P(:, 0:3) S^-1 (H = [I 0]); S symmetric, so K' = S^-1 P(0:3, :).
  const Eigen::Matrix<double, 6, 3> K = S.solve(P_.topRows<3>()).transpose();
  x_ += K * y;
  // Joseph form keeps P symmetric and positive definite: (I - K H) P (I - K H)' + K R K'.
  Covariance IKH = Covariance::Identity();
  IKH.leftCols<3>() -= K;
  const double r = noise_.measurementSigma * noise_.measurementSigma;
  P_ = IKH * P_ * IKH.transpose() + r * K * K.transpose();
}

double ConstantVelocityKalman::mahalanobis2(const Eigen::Vector3d& measured) const {
  const Eigen::Vector3d y = measured - position();
  return y.dot(innovationCovariance().llt().solve(y));
}

}  // namespace fusedet::tracking
