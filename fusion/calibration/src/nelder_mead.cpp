// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/nelder_mead.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <vector>

namespace fusedet::fusion {

NelderMeadResult minimiseNelderMead(const std::function<double(const Eigen::VectorXd&)>& f,
                                    const Eigen::VectorXd& x0, const Eigen::VectorXd& step,
                                    const NelderMeadOptions& options) {
  const Eigen::Index n = x0.size();
  if (n == 0 || step.size() != n) throw std::invalid_argument("Nelder-Mead: x0 and step must have the same, non-zero size");
  constexpr double kReflect = 1.0, kExpand = 2.0, kContract = 0.5, kShrink = 0.5;
  NelderMeadResult result;
  auto eval = [&](const Eigen::VectorXd& x) {
    ++result.evaluations;
    return f(x);
  };
  std::vector<Eigen::VectorXd> xs(static_cast<std::size_t>(n + 1), x0);
  std::vector<double> fs(xs.size());
  for (Eigen::Index i = 0; i < n; ++i) xs[static_cast<std::size_t>(i + 1)](i) += step(i);
  for (std::size_t i = 0; i < xs.size(); ++i) fs[i] = eval(xs[i]);
  std::vector<std::size_t> order(xs.size());
  while (true) {
    std::iota(order.begin(), order.end(), 0);
    // Ties go to the lower index so the run is deterministic.
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return fs[a] < fs[b]; });
    const std::size_t best = order.front(), worst = order.back(), second = order[order.size() - 2];
    double spread = 0;
    for (const auto& x : xs) spread = std::max(spread, (x - xs[best]).cwiseAbs().maxCoeff());
    if (spread <= options.xTolerance && fs[worst] - fs[best] <= options.fTolerance) {
      result.converged = true;
      break;
    }
    if (result.evaluations >= options.maxEvaluations) break;
    Eigen::VectorXd centroid = Eigen::VectorXd::Zero(n);
    for (std::size_t i = 0; i < xs.size(); ++i)
      if (i != worst) centroid += xs[i];
    centroid /= static_cast<double>(n);
    const Eigen::VectorXd reflected = centroid + kReflect * (centroid - xs[worst]);
    const double fr = eval(reflected);
    if (fr < fs[best]) {
      const Eigen::VectorXd expanded = centroid + kExpand * (reflected - centroid);
      const double fe = eval(expanded);
      if (fe < fr) {
        xs[worst] = expanded;
        fs[worst] = fe;
      } else {
        xs[worst] = reflected;
        fs[worst] = fr;
      }
      continue;
    }
    if (fr < fs[second]) {
      xs[worst] = reflected;
      fs[worst] = fr;
      continue;
    }
    // Contract towards the better of the worst and the reflected point.
    const bool outside = fr < fs[worst];
    const Eigen::VectorXd contracted =
        outside ? Eigen::VectorXd(centroid + kContract * (reflected - centroid))
                : Eigen::VectorXd(centroid + kContract * (xs[worst] - centroid));
    const double fc = eval(contracted);
    if (fc < (outside ? fr : fs[worst])) {
      xs[worst] = contracted;
      fs[worst] = fc;
      continue;
    }
    for (std::size_t i = 0; i < xs.size(); ++i) {
      if (i == best) continue;
      xs[i] = xs[best] + kShrink * (xs[i] - xs[best]);
      fs[i] = eval(xs[i]);
    }
  }
  const std::size_t best = static_cast<std::size_t>(std::min_element(fs.begin(), fs.end()) - fs.begin());
  result.x = xs[best];
  result.value = fs[best];
  return result;
}

}  // namespace fusedet::fusion
