// SPDX-License-Identifier: Apache-2.0
// ConstantVelocityKalman against worked examples computed by hand (one axis: the axes are
// independent, so every axis shows the same numbers).
#include <gtest/gtest.h>

#include "fusedet/tracking/kalman.h"

using fusedet::tracking::ConstantVelocityKalman;
using fusedet::tracking::KalmanNoise;

namespace {
KalmanNoise noise(double a, double m, double v0) {
  KalmanNoise n;
  n.accelerationSigma = a;
  n.measurementSigma = m;
  n.initialVelocitySigma = v0;
  return n;
}
}  // namespace

TEST(Kalman, BirthStateAndCovariance) {
  const ConstantVelocityKalman k({1, 2, 3}, noise(1, 0.5, 2));
  EXPECT_EQ(k.position(), Eigen::Vector3d(1, 2, 3));
  EXPECT_EQ(k.velocity(), Eigen::Vector3d::Zero());
  EXPECT_DOUBLE_EQ(k.covariance()(0, 0), 0.25);
  EXPECT_DOUBLE_EQ(k.covariance()(3, 3), 4.0);
  EXPECT_DOUBLE_EQ(k.covariance()(0, 3), 0.0);
}

TEST(Kalman, PredictWorkedExample) {
  // Per axis P = [0.25 0; 0 4], dt = 2, a = 1:
  // F P F' = [0.25 + 4*4, 2*4; 8, 4] = [16.25 8; 8 4]; Q = [16/4 8/2; 4 4] = [4 4; 4 4]
  // -> P = [20.25 12; 12 8].
  ConstantVelocityKalman k({0, 0, 0}, noise(1, 0.5, 2));
  k.predict(2);
  for (int axis = 0; axis < 3; ++axis) {
    EXPECT_NEAR(k.covariance()(axis, axis), 20.25, 1e-12);
    EXPECT_NEAR(k.covariance()(axis, axis + 3), 12, 1e-12);
    EXPECT_NEAR(k.covariance()(axis + 3, axis), 12, 1e-12);
    EXPECT_NEAR(k.covariance()(axis + 3, axis + 3), 8, 1e-12);
  }
  EXPECT_NEAR(k.covariance()(0, 1), 0, 1e-12);
  EXPECT_EQ(k.position(), Eigen::Vector3d::Zero());
}

TEST(Kalman, UpdateWorkedExample) {
  // After the prediction above, per axis P = [20.25 12; 12 8], R = 0.25, S = 20.5.
  // Measured x = 4.1 (y = 4.1): K = [20.25/20.5, 12/20.5] = [0.987805, 0.585366];
  // x = [4.05, 2.4]; P = (I - K H) P (...)' + K R K' = [20.25 - 20.25^2/20.5, 12 - 20.25*12/20.5;
  // ., 8 - 144/20.5] = [0.246951, 0.146341; 0.146341, 0.975610].
  ConstantVelocityKalman k({0, 0, 0}, noise(1, 0.5, 2));
  k.predict(2);
  EXPECT_NEAR(k.mahalanobis2({4.1, 0, 0}), 4.1 * 4.1 / 20.5, 1e-12);
  k.update({4.1, 0, 0});
  EXPECT_NEAR(k.position().x(), 4.1 * 20.25 / 20.5, 1e-12);
  EXPECT_NEAR(k.velocity().x(), 4.1 * 12 / 20.5, 1e-12);
  EXPECT_NEAR(k.position().y(), 0, 1e-12);
  EXPECT_NEAR(k.covariance()(0, 0), 20.25 - 20.25 * 20.25 / 20.5, 1e-12);
  EXPECT_NEAR(k.covariance()(0, 3), 12 - 20.25 * 12 / 20.5, 1e-12);
  EXPECT_NEAR(k.covariance()(3, 3), 8 - 144 / 20.5, 1e-12);
}

TEST(Kalman, ConvergesToAConstantVelocity) {
  // A target moving at (1, -0.5, 0) m/s measured exactly every 0.1 s: the velocity converges.
  ConstantVelocityKalman k({0, 0, 0}, noise(0.5, 0.1, 5));
  for (int i = 1; i <= 100; ++i) {
    k.predict(0.1);
    k.update({0.1 * i, -0.05 * i, 0});
  }
  EXPECT_NEAR(k.velocity().x(), 1.0, 1e-3);
  EXPECT_NEAR(k.velocity().y(), -0.5, 1e-3);
  EXPECT_NEAR(k.position().x(), 10.0, 1e-3);
}

TEST(Kalman, RejectsNegativeTime) {
  ConstantVelocityKalman k({0, 0, 0}, KalmanNoise{});
  EXPECT_THROW(k.predict(-0.1), std::invalid_argument);
  k.predict(0);  // no-op
  EXPECT_DOUBLE_EQ(k.covariance()(0, 0), KalmanNoise{}.measurementSigma * KalmanNoise{}.measurementSigma);
}
