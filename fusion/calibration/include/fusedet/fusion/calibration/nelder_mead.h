// SPDX-License-Identifier: Apache-2.0
#pragma once
// Nelder-Mead downhill simplex (Nelder & Mead 1965; Lagarias et al. 1998 coefficients): a
// derivative-free minimiser for the calibration costs, which are piecewise constant at the scale of
// a pixel and have no useful gradient.

#include <Eigen/Core>
#include <functional>

namespace fusedet::fusion {

struct NelderMeadOptions {
  int maxEvaluations = 2000;
  double xTolerance = 1e-3;  // stop when every vertex is this close (max-norm) to the best one
  double fTolerance = 1e-9;  // ... and the values differ by at most this
};

struct NelderMeadResult {
  Eigen::VectorXd x;
  double value = 0;
  int evaluations = 0;
  bool converged = false;  // false: stopped by maxEvaluations
};

// Minimises f from x0; the start simplex is x0 plus step(i) along each axis i.
NelderMeadResult minimiseNelderMead(const std::function<double(const Eigen::VectorXd&)>& f,
                                    const Eigen::VectorXd& x0, const Eigen::VectorXd& step,
                                    const NelderMeadOptions& options = {});

}  // namespace fusedet::fusion
