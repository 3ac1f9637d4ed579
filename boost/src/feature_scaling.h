#pragma once
// Column standardisation shared by the two fitters of grouped-detection features (box_regression.cpp,
// group_verifier.cpp): both fit a linear model on z-scored features and keep mean and scale, so that
// a prediction applies the same map to a new detection's features.

#include <Eigen/Core>
#include <span>
#include <vector>

namespace fusedet::boosting {

// True when every value is finite (a fit leaves out a row holding a NaN or an infinity).
bool allFinite(std::span<const double> values);

struct ColumnScaling {
  std::vector<double> mean, scale;  // per column: z = (x - mean) / scale
};

// Centres every column of `x` (at least one row) on its mean and divides it by its population
// standard deviation, in place. A column that is constant over the rows (sd < 1e-12), or that `used`
// marks false, becomes all 0 with scale 1: it carries no information, so its fitted weight stays 0.
// `used` empty = every column.
ColumnScaling standardiseColumns(Eigen::Ref<Eigen::MatrixXd> x, const std::vector<bool>& used = {});

}  // namespace fusedet::boosting
