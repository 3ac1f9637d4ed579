#include "feature_scaling.h"

#include <algorithm>
#include <cmath>

namespace fusedet::boosting {

bool allFinite(std::span<const double> values) {
  return std::all_of(values.begin(), values.end(), [](double x) { return std::isfinite(x); });
}

ColumnScaling standardiseColumns(Eigen::Ref<Eigen::MatrixXd> x, const std::vector<bool>& used) {
  const Eigen::Index n = x.rows(), d = x.cols();
  const Eigen::RowVectorXd mean = x.colwise().mean();
  x.rowwise() -= mean;
  Eigen::RowVectorXd sd = (x.colwise().squaredNorm() / static_cast<double>(n)).cwiseSqrt();
  for (Eigen::Index j = 0; j < d; ++j)
    if (sd(j) < 1e-12 || (!used.empty() && !used[static_cast<std::size_t>(j)])) {
      sd(j) = 1;
      x.col(j).setZero();
    }
  x.array().rowwise() /= sd.array();
  return {{mean.data(), mean.data() + d}, {sd.data(), sd.data() + d}};
}

}  // namespace fusedet::boosting
