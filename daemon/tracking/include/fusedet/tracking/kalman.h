// SPDX-License-Identifier: Apache-2.0
#pragma once
// ConstantVelocityKalman: one object's 3D position and velocity in the robot frame, a linear
// Kalman filter with a constant-velocity motion model (state [x y z vx vy vz]) and
// white-acceleration process noise, measured by a 3D position (the laser's).

#include <Eigen/Core>

namespace fusedet::tracking {

struct KalmanNoise {
  double accelerationSigma = 2.0;     // m/s^2: white acceleration (process noise) per axis
  double measurementSigma = 0.5;      // m: position measurement noise per axis
  double initialVelocitySigma = 5.0;  // m/s: velocity uncertainty of a new track per axis
};

class ConstantVelocityKalman {
 public:
  using State = Eigen::Matrix<double, 6, 1>;
  using Covariance = Eigen::Matrix<double, 6, 6>;

  // A track born at `position` with velocity 0: covariance diag(measurementSigma^2 x3,
  // initialVelocitySigma^2 x3).
  ConstantVelocityKalman(const Eigen::Vector3d& position, const KalmanNoise& noise);

  // Moves the state dt seconds ahead (dt >= 0): x = F x, P = F P F' + Q, with per axis
  // Q = a^2 [dt^4/4, dt^3/2; dt^3/2, dt^2] (a = accelerationSigma).
  void predict(double dt);
  // Corrects with a measured position: K = P H' S^-1, S = H P H' + R, R = measurementSigma^2 I.
  void update(const Eigen::Vector3d& measured);
  // Squared Mahalanobis distance of a measured position from the current state: y' S^-1 y,
  // y = measured - position().
  double mahalanobis2(const Eigen::Vector3d& measured) const;

  Eigen::Vector3d position() const { return x_.head<3>(); }
  Eigen::Vector3d velocity() const { return x_.tail<3>(); }
  const State& state() const { return x_; }
  const Covariance& covariance() const { return P_; }

 private:
  Eigen::Matrix3d innovationCovariance() const;

  KalmanNoise noise_;
  State x_;
  Covariance P_;
};

}  // namespace fusedet::tracking
