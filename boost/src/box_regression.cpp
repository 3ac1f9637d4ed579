#include "fusedet/boost/box_regression.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "feature_scaling.h"
#include "fusedet/boost/laser_extent.h"

namespace fusedet::boosting {

namespace {

constexpr std::size_t kFeatures = 4 + 16 + 1 + 2 + 3 + 5;

}  // namespace

std::size_t boxFeatureCount() { return kFeatures; }

BoxTargets boxTargets(const Box& box, const Box& truth) {
  return {(truth.centerX() - box.centerX()) / box.w, (truth.centerY() - box.centerY()) / box.h,
          std::log(truth.w / box.w), std::log(truth.h / box.h)};
}

Box applyTargets(const Box& box, const BoxTargets& t) {
  const double w = box.w * std::exp(t[2]), h = box.h * std::exp(t[3]);
  const double cx = box.centerX() + t[0] * box.w, cy = box.centerY() + t[1] * box.h;
  return Box{cx - w / 2, cy - h / 2, w, h};
}

std::vector<double> boxFeatures(const GroupedBox& g, const LayerStack& stack) {
  const Box& b = g.box;
  std::vector<double> f;
  f.reserve(kFeatures);
  if (!(b.w > 0) || !(b.h > 0)) return std::vector<double>(kFeatures, 0.0);
  // Edges of a box relative to the base box: left, top, right, bottom offsets by its size.
  const auto edges = [&](const Box& o) {
    return std::array<double, 4>{(o.x - b.x) / b.w, (o.y - b.y) / b.h, (o.right() - b.right()) / b.w,
                                 (o.bottom() - b.bottom()) / b.h};
  };
  for (double e : edges(g.groupBox)) f.push_back(e);
  const std::vector<Box> members = g.members.empty() ? std::vector<Box>{g.groupBox} : g.members;
  for (int k = 0; k < 4; ++k) {
    double sum = 0, sq = 0, lo = 1e9, hi = -1e9;
    for (const Box& m : members) {
      const double e = edges(m)[static_cast<std::size_t>(k)];
      sum += e;
      sq += e * e;
      lo = std::min(lo, e);
      hi = std::max(hi, e);
    }
    const double n = static_cast<double>(members.size()), mean = sum / n;
    f.insert(f.end(), {mean, std::sqrt(std::max(0.0, sq / n - mean * mean)), lo, hi});
  }
  f.push_back(std::log1p(static_cast<double>(g.members.size())));
  LaserExtentParams extent;  // the general rule, measured whatever the class's setting
  extent.enabled = true;
  const std::array<double, 4> ex = edges(laserExtentBox(b, stack, extent));
  f.insert(f.end(), {ex[0], ex[2]});
  if (const std::optional<LaserRows> rows = laserRows(b, stack, extent))
    f.insert(f.end(), {(rows->top - b.y) / b.h, (rows->bottom - b.bottom()) / b.h, 1.0});
  else
    f.insert(f.end(), {0.0, 0.0, 0.0});
  const double W = std::max(1, stack.width()), H = std::max(1, stack.height());
  f.insert(f.end(), {std::log(b.w / b.h), std::log(b.h / H), b.bottom() / H, std::max(0.0, b.x) / W,
                     std::max(0.0, W - b.right()) / W});
  for (double& v : f)
    if (!std::isfinite(v)) v = 0;  // a degenerate member or layer value carries no information
  return f;
}

BoxRegression fitBoxRegression(const std::vector<std::vector<double>>& features, const std::vector<BoxTargets>& targets,
                               const BoxFitParams& params) {
  if (!(params.lambda > 0)) throw std::invalid_argument("fitBoxRegression: lambda must be > 0");
  if (features.size() != targets.size())
    throw std::invalid_argument("fitBoxRegression: " + std::to_string(features.size()) + " feature rows but " +
                                std::to_string(targets.size()) + " targets");
  const std::size_t dims = features.empty() ? 0 : features.front().size();
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < features.size(); ++i) {
    if (features[i].size() != dims) throw std::invalid_argument("fitBoxRegression: feature rows differ in length");
    if (allFinite(features[i]) && allFinite(targets[i])) rows.push_back(i);
  }
  BoxRegression out;
  out.lambda = params.lambda;
  out.maxShift = params.maxShift;
  out.maxScale = params.maxScale;
  out.samples = rows.size();
  if (rows.size() < std::max<std::size_t>(1, params.minSamples) || dims == 0) {
    out.why = std::to_string(rows.size()) + " usable samples, " + std::to_string(params.minSamples) + " needed" +
              (dims == 0 ? ", no features" : "");
    return out;
  }
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size()), d = static_cast<Eigen::Index>(dims);
  Eigen::MatrixXd X(n, d), Y(n, 4);
  for (Eigen::Index i = 0; i < n; ++i) {
    for (Eigen::Index j = 0; j < d; ++j) X(i, j) = features[rows[static_cast<std::size_t>(i)]][static_cast<std::size_t>(j)];
    for (Eigen::Index t = 0; t < 4; ++t) Y(i, t) = targets[rows[static_cast<std::size_t>(i)]][static_cast<std::size_t>(t)];
  }
  ColumnScaling scaling = standardiseColumns(X);  // a constant feature gets weight 0
  const Eigen::RowVectorXd ymu = Y.colwise().mean();
  Y.rowwise() -= ymu;
  // Centred data: the intercept is the targets' mean and is not penalised.
  Eigen::MatrixXd A = X.transpose() * X;
  A.diagonal().array() += params.lambda;
  const Eigen::MatrixXd Wt = A.ldlt().solve(X.transpose() * Y);
  if (!Wt.allFinite()) {
    out.why = "the ridge system has no finite solution";
    return out;
  }
  out.mean = std::move(scaling.mean);
  out.scale = std::move(scaling.scale);
  out.weights.resize(dims);
  for (Eigen::Index j = 0; j < d; ++j)
    for (Eigen::Index t = 0; t < 4; ++t) out.weights[static_cast<std::size_t>(j)][static_cast<std::size_t>(t)] = Wt(j, t);
  for (Eigen::Index t = 0; t < 4; ++t) out.intercept[static_cast<std::size_t>(t)] = ymu(t);
  return out;
}

BoxTargets BoxRegression::predict(std::span<const double> features) const {
  BoxTargets t{};
  if (!fitted()) return t;
  if (features.size() != weights.size())
    throw std::invalid_argument("BoxRegression: " + std::to_string(features.size()) + " features, fitted on " +
                                std::to_string(weights.size()));
  t = intercept;
  for (std::size_t j = 0; j < weights.size(); ++j) {
    const double z = (features[j] - mean[j]) / scale[j];
    for (std::size_t k = 0; k < 4; ++k) t[k] += weights[j][k] * z;
  }
  const double shift = std::abs(maxShift), logScale = std::log(std::max(1.0, maxScale));
  for (std::size_t k = 0; k < 4; ++k) {
    const double limit = k < 2 ? shift : logScale;
    t[k] = std::isfinite(t[k]) ? std::clamp(t[k], -limit, limit) : 0.0;
  }
  return t;
}

Box BoxRegression::refine(const GroupedBox& g, const LayerStack& stack) const {
  if (!fitted() || !(g.box.w > 0) || !(g.box.h > 0)) return g.box;
  return applyTargets(g.box, predict(boxFeatures(g, stack)));
}

}  // namespace fusedet::boosting
