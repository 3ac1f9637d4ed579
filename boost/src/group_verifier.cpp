#include "fusedet/boost/group_verifier.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <numeric>
#include <opencv2/core.hpp>
#include <stdexcept>
#include <utility>

#include "feature_scaling.h"
#include "fusedet/boost/laser_cells.h"

namespace fusedet::boosting {

namespace {

constexpr std::size_t kMarginFeatures = 3, kLaserFeatures = 6, kHeightFeatures = 3, kSquareFeatures = 2;
constexpr int kMinLaserCells = 6;  // as the laser extent's reference distance needs

// Measured values of `layer` (the height layer; the distance layer is read through laser_cells.h)
// inside the rows [top, bottom) and columns [left, right) given as fractions of `box` (reference
// pixels); `cells` gets the number of cells looked at.
std::vector<float> valuesIn(const Layer& layer, const LayerStack& stack, const Box& box, double left, double right,
                            double top, double bottom, std::size_t& cells) {
  std::vector<float> out;
  cells = 0;
  if (layer.data.empty() || stack.width() <= 0 || stack.height() <= 0) return out;
  const Box part{box.x + left * box.w, box.y + top * box.h, (right - left) * box.w, (bottom - top) * box.h};
  const Box px = LayerStack::toLayerPixels(layer, stack.toUnit(part));
  const int c0 = std::clamp(static_cast<int>(std::floor(px.x)), 0, layer.width());
  const int c1 = std::clamp(static_cast<int>(std::ceil(px.right())), c0, layer.width());
  const int r0 = std::clamp(static_cast<int>(std::floor(px.y)), 0, layer.height());
  const int r1 = std::clamp(static_cast<int>(std::ceil(px.bottom())), r0, layer.height());
  cv::Mat1f v;
  layer.data(cv::Range(r0, r1), cv::Range(c0, c1)).convertTo(v, CV_32F);
  for (int r = 0; r < v.rows; ++r)
    for (int c = 0; c < v.cols; ++c) {
      ++cells;
      const float x = v(r, c);
      if (std::isfinite(x) && (layer.valid.empty() || layer.valid.at<std::uint8_t>(r0 + r, c0 + c) != 0))
        out.push_back(x);
    }
  return out;
}

// The q-quantile (nearest rank) of non-empty `v` (reordered).
double quantile(std::vector<float>& v, double q) {
  const std::size_t k = std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())));
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(k), v.end());
  return v[k];
}

}  // namespace

std::size_t groupFeatureCount() {
  return boxFeatureCount() + kMarginFeatures + kLaserFeatures + kHeightFeatures + kSquareFeatures;
}
std::size_t laserSeenIndex() { return boxFeatureCount() + kMarginFeatures; }
std::size_t pixelMetreHeightIndex() { return laserSeenIndex() + 4; }

std::vector<std::size_t> featureSet(VerifierParams::Features set) {
  std::vector<std::size_t> out;
  if (set == VerifierParams::Features::kAll) {
    out.resize(groupFeatureCount());
    std::iota(out.begin(), out.end(), 0);
    return out;
  }
  // boxFeatures(): 20 = log(1 + members), 26 = log aspect, 27 = log height (box_regression.cpp).
  out = set == VerifierParams::Features::kCompact ? std::vector<std::size_t>{20, 26, 27} : std::vector<std::size_t>{20};
  const std::size_t from = set == VerifierParams::Features::kCompact ? boxFeatureCount() : laserSeenIndex();
  for (std::size_t j = from; j < groupFeatureCount(); ++j) out.push_back(j);
  return out;
}

std::vector<double> groupFeatures(const GroupedBox& g, const LayerStack& stack) {
  std::vector<double> f = boxFeatures(g, stack);
  f.reserve(groupFeatureCount());
  // Cascade margins: the members' last-stage sums.
  if (g.memberScores.empty()) {
    f.insert(f.end(), kMarginFeatures, 0.0);
  } else {
    const auto [lo, hi] = std::minmax_element(g.memberScores.begin(), g.memberScores.end());
    f.insert(f.end(), {std::accumulate(g.memberScores.begin(), g.memberScores.end(), 0.0) /
                           static_cast<double>(g.memberScores.size()),
                       *hi, *lo});
  }
  const Box& b = g.box;
  const bool sized = b.w > 0 && b.h > 0;
  // Laser: the valid distance cells of the box's core (laser_cells.h: the band's middle columns).
  std::size_t cells = 0;
  std::vector<float> d;
  if (const LaserCells laser(stack); !laser.empty() && sized) {
    const LaserCells::Place at = laser.place(b);
    for (int r = at.bandTop; r < at.bandEnd; ++r)
      for (int c = at.coreFirst; c <= at.coreLast; ++c, ++cells)
        if (laser.valid(r, c)) d.push_back(laser.distance(r, c));
  }
  if (static_cast<int>(d.size()) >= kMinLaserCells) {
    const double share = static_cast<double>(d.size()) / static_cast<double>(std::max<std::size_t>(1, cells));
    const double median = quantile(d, 0.5), q1 = quantile(d, 0.25), q3 = quantile(d, 0.75);
    f.insert(f.end(), {1.0, share, std::log(median), (q3 - q1) / median, std::log(b.h * median), std::log(b.w * median)});
  } else {
    f.insert(f.end(), {0.0, cells ? static_cast<double>(d.size()) / static_cast<double>(cells) : 0.0, 0.0, 0.0, 0.0, 0.0});
  }
  // Height above the fitted ground plane: the object's top, and where it stands.
  std::vector<float> all, bottom;
  if (const Layer* layer = stack.find(kHeightLayerName); layer && sized) {
    all = valuesIn(*layer, stack, b, 0, 1, 0, 1, cells);
    bottom = valuesIn(*layer, stack, b, 0, 1, 0.8, 1, cells);
  }
  if (!all.empty())
    f.insert(f.end(), {1.0, quantile(all, 0.9), bottom.empty() ? 0.0 : quantile(bottom, 0.1)});
  else
    f.insert(f.end(), {0.0, 0.0, 0.0});
  const double pmh = f[pixelMetreHeightIndex()], top = f[laserSeenIndex() + kLaserFeatures + 1];
  f.insert(f.end(), {pmh * pmh, top * top});
  for (double& v : f)
    if (!std::isfinite(v)) v = 0;
  return f;
}

double GroupVerifier::probability(std::span<const double> features) const {
  if (!ready || kind != VerifierParams::Kind::kLogistic) return 0.5;
  if (features.size() != weights.size())
    throw std::invalid_argument("GroupVerifier: " + std::to_string(features.size()) + " features, fitted on " +
                                std::to_string(weights.size()));
  double z = intercept;
  for (std::size_t j = 0; j < weights.size(); ++j) z += weights[j] * (features[j] - mean[j]) / scale[j];
  return 1 / (1 + std::exp(-std::clamp(z, -40.0, 40.0)));
}

bool GroupVerifier::accepts(std::span<const double> features) const {
  if (!ready) return true;
  if (kind == VerifierParams::Kind::kLogistic) return probability(features) >= threshold;
  if (features.size() <= pixelMetreHeightIndex()) return true;
  if (features[laserSeenIndex()] == 0) return true;  // no laser on it: nothing to judge by
  const double h = features[pixelMetreHeightIndex()];
  return h >= gateLow && h <= gateHigh;
}

double GroupVerifier::score(std::span<const double> features, double groupScore) const {
  return ready && rescore && kind == VerifierParams::Kind::kLogistic ? probability(features) : groupScore;
}

GroupVerifier fitGroupVerifier(const std::vector<std::vector<double>>& features, const std::vector<bool>& isHit,
                               std::size_t positives, const VerifierParams& params) {
  if (!(params.lambda > 0)) throw std::invalid_argument("fitGroupVerifier: lambda must be > 0");
  if (features.size() != isHit.size())
    throw std::invalid_argument("fitGroupVerifier: " + std::to_string(features.size()) + " feature rows but " +
                                std::to_string(isHit.size()) + " labels");
  const std::size_t dims = features.empty() ? 0 : features.front().size();
  std::vector<std::size_t> rows;
  for (std::size_t i = 0; i < features.size(); ++i) {
    if (features[i].size() != dims) throw std::invalid_argument("fitGroupVerifier: feature rows differ in length");
    if (allFinite(features[i])) rows.push_back(i);
  }
  GroupVerifier out;
  out.kind = params.kind;
  out.rescore = params.rescore;
  out.lambda = params.lambda;
  out.samples = rows.size();
  for (std::size_t i : rows) out.hits += isHit[i] ? 1 : 0;
  if (dims == 0 || rows.size() < std::max<std::size_t>(1, params.minSamples)) {
    out.why = std::to_string(rows.size()) + " usable samples, " + std::to_string(params.minSamples) + " needed" +
              (dims == 0 ? ", no features" : "");
    return out;
  }
  if (params.kind == VerifierParams::Kind::kHeightGate) {
    if (dims <= pixelMetreHeightIndex()) {
      out.why = "no height feature";
      return out;
    }
    std::vector<float> h;
    for (std::size_t i : rows)
      if (isHit[i] && features[i][laserSeenIndex()] != 0) h.push_back(static_cast<float>(features[i][pixelMetreHeightIndex()]));
    if (h.size() < std::max<std::size_t>(1, params.minSamples)) {
      out.why = std::to_string(h.size()) + " hits with laser cells, " + std::to_string(params.minSamples) + " needed";
      return out;
    }
    out.gateLow = quantile(h, params.gateLow);
    out.gateHigh = quantile(h, params.gateHigh);
    out.ready = true;
    return out;
  }
  if (out.hits == 0 || out.hits == rows.size()) {
    out.why = out.hits == 0 ? "no hit among the samples" : "no false alarm among the samples";
    return out;
  }
  const Eigen::Index n = static_cast<Eigen::Index>(rows.size()), d = static_cast<Eigen::Index>(dims);
  Eigen::MatrixXd X(n, d + 1);
  Eigen::VectorXd y(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const std::size_t r = rows[static_cast<std::size_t>(i)];
    for (Eigen::Index j = 0; j < d; ++j) X(i, j) = features[r][static_cast<std::size_t>(j)];
    y(i) = isHit[r] ? 1 : 0;
  }
  std::vector<bool> used(dims, false);
  for (std::size_t j : featureSet(params.features))
    if (j < dims) used[j] = true;
  if (params.features == VerifierParams::Features::kAll) used.assign(dims, true);
  ColumnScaling scaling = standardiseColumns(X.leftCols(d), used);  // constant or left out: weight 0
  X.col(d).setOnes();  // intercept, not penalised
  Eigen::VectorXd penalty = Eigen::VectorXd::Constant(d + 1, params.lambda);
  penalty(d) = 0;
  Eigen::VectorXd w = Eigen::VectorXd::Zero(d + 1);
  for (int it = 0; it < params.maxIterations; ++it) {
    const Eigen::VectorXd p = (1.0 / (1.0 + (-(X * w).array().cwiseMax(-40.0).cwiseMin(40.0)).exp())).matrix();
    const Eigen::VectorXd wts = (p.array() * (1 - p.array())).max(1e-10).matrix();
    const Eigen::VectorXd grad = X.transpose() * (p - y) + penalty.cwiseProduct(w);
    Eigen::MatrixXd H = X.transpose() * wts.asDiagonal() * X;
    H.diagonal() += penalty;
    H.diagonal().array() += 1e-9;  // keeps the intercept's row regular when every weight is tiny
    const Eigen::VectorXd step = H.ldlt().solve(grad);
    if (!step.allFinite()) break;
    w -= step;
    if (step.lpNorm<Eigen::Infinity>() < 1e-9) break;
  }
  if (!w.allFinite()) {
    out.why = "the logistic fit has no finite solution";
    return out;
  }
  out.mean = std::move(scaling.mean);
  out.scale = std::move(scaling.scale);
  out.weights.assign(w.data(), w.data() + d);
  out.intercept = w(d);
  out.ready = true;
  // Operating threshold: the highest training F = 2 hits / (kept detections + positives).
  std::vector<std::pair<double, bool>> scored;
  for (std::size_t i : rows) scored.emplace_back(out.probability(features[i]), isHit[i]);
  std::sort(scored.begin(), scored.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
  const double allPositives = static_cast<double>(std::max(positives, out.hits));
  double bestF = -1;
  std::size_t h = 0;
  for (std::size_t k = 0; k < scored.size(); ++k) {
    h += scored[k].second ? 1 : 0;
    if (k + 1 < scored.size() && scored[k + 1].first == scored[k].first) continue;  // ties go together
    const double f = 2.0 * static_cast<double>(h) / (static_cast<double>(k + 1) + allPositives);
    if (f > bestF) {
      bestF = f;
      out.threshold = scored[k].first;
    }
  }
  out.trainingF = std::max(0.0, bestF);
  return out;
}

void verifyGroups(std::vector<Detection>& detections, const std::vector<GroupedBox>& groups,
                  std::vector<std::vector<HitFate>>& fates, const LayerStack& stack, const GroupVerifier& verifier) {
  if (!verifier.fitted()) return;
  if (groups.size() != detections.size())
    throw std::invalid_argument("verifyGroups: " + std::to_string(groups.size()) + " groups for " +
                                std::to_string(detections.size()) + " detections");
  std::vector<int> renumber(detections.size(), -1);
  std::vector<Detection> kept;
  for (std::size_t i = 0; i < detections.size(); ++i) {
    const std::vector<double> f = groupFeatures(groups[i], stack);
    if (!verifier.accepts(f)) continue;
    renumber[i] = static_cast<int>(kept.size());
    kept.push_back(detections[i]);
    kept.back().score = verifier.score(f, detections[i].score);
  }
  for (auto& list : fates)
    for (HitFate& fate : list) {
      if (fate.detection < 0 || static_cast<std::size_t>(fate.detection) >= renumber.size()) continue;
      fate.detection = renumber[static_cast<std::size_t>(fate.detection)];
      if (fate.detection < 0 && fate.outcome == HitFate::Outcome::kKept) fate.outcome = HitFate::Outcome::kTooFewNeighbours;
    }
  detections = std::move(kept);
}

}  // namespace fusedet::boosting
