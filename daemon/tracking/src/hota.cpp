// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/hota.h"

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include "fusedet/tracking/assignment.h"

namespace fusedet::tracking {
namespace {

double mean(const std::array<double, Hota::kAlphas>& v) {
  return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(Hota::kAlphas);
}

using Pair = std::pair<std::int64_t, std::int64_t>;  // (truth id, hypothesis id)

Eigen::MatrixXd similarities(const MotFrame& f) {
  Eigen::MatrixXd s(static_cast<Eigen::Index>(f.truth.size()), static_cast<Eigen::Index>(f.hypotheses.size()));
  for (std::size_t i = 0; i < f.truth.size(); ++i)
    for (std::size_t j = 0; j < f.hypotheses.size(); ++j)
      s(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = iou(f.truth[i].box, f.hypotheses[j].box);
  return s;
}

}  // namespace

double Hota::meanHota() const { return mean(hota); }
double Hota::meanDetA() const { return mean(detA); }
double Hota::meanAssA() const { return mean(assA); }
double Hota::meanLocA() const { return mean(locA); }

Hota hota(const MotSequence& sequence) {
  constexpr double kEps = std::numeric_limits<double>::epsilon();
  // Pass 1: how often each id appears and the pairs' potential matches (each frame's IoU
  // normalised by the rows' and columns' summed similarity, as a soft one-to-one share).
  std::map<std::int64_t, double> truthCount, hypCount;
  std::map<Pair, double> potential;
  for (const MotFrame& f : sequence) {
    const Eigen::MatrixXd s = similarities(f);
    const Eigen::VectorXd rowSum = s.rowwise().sum();
    const Eigen::RowVectorXd colSum = s.colwise().sum();
    for (Eigen::Index i = 0; i < s.rows(); ++i)
      for (Eigen::Index j = 0; j < s.cols(); ++j) {
        const double denom = rowSum(i) + colSum(j) - s(i, j);
        if (denom > kEps && s(i, j) > 0)
          potential[{f.truth[static_cast<std::size_t>(i)].id, f.hypotheses[static_cast<std::size_t>(j)].id}] += s(i, j) / denom;
      }
    for (const MotObject& t : f.truth) truthCount[t.id] += 1;
    for (const MotObject& h : f.hypotheses) hypCount[h.id] += 1;
  }
  auto alignment = [&](std::int64_t t, std::int64_t h) {
    const auto it = potential.find({t, h});
    if (it == potential.end()) return 0.0;
    return it->second / (truthCount[t] + hypCount[h] - it->second);
  };
  // Pass 2: per frame the assignment maximising alignment x IoU, scored at every alpha.
  std::array<double, Hota::kAlphas> tp{}, fn{}, fp{}, locSum{};
  std::array<std::map<Pair, double>, Hota::kAlphas> matches;
  constexpr double kForbidden = std::numeric_limits<double>::infinity();
  for (const MotFrame& f : sequence) {
    const Eigen::MatrixXd s = similarities(f);
    Eigen::MatrixXd cost(s.rows(), s.cols());
    for (Eigen::Index i = 0; i < s.rows(); ++i)
      for (Eigen::Index j = 0; j < s.cols(); ++j) {
        const double score = alignment(f.truth[static_cast<std::size_t>(i)].id, f.hypotheses[static_cast<std::size_t>(j)].id) * s(i, j);
        cost(i, j) = score > 0 ? -score : kForbidden;
      }
    const std::vector<int> match = assign(cost, 0.0);
    for (int a = 0; a < Hota::kAlphas; ++a) {
      double n = 0;
      for (Eigen::Index i = 0; i < s.rows(); ++i) {
        const int j = match[static_cast<std::size_t>(i)];
        if (j < 0 || s(i, j) < Hota::alpha(a) - kEps) continue;
        n += 1;
        locSum[static_cast<std::size_t>(a)] += s(i, j);
        matches[static_cast<std::size_t>(a)][{f.truth[static_cast<std::size_t>(i)].id, f.hypotheses[static_cast<std::size_t>(j)].id}] += 1;
      }
      tp[static_cast<std::size_t>(a)] += n;
      fn[static_cast<std::size_t>(a)] += static_cast<double>(f.truth.size()) - n;
      fp[static_cast<std::size_t>(a)] += static_cast<double>(f.hypotheses.size()) - n;
    }
  }
  Hota r;
  for (std::size_t a = 0; a < Hota::kAlphas; ++a) {
    double assSum = 0;
    for (const auto& [pair, m] : matches[a]) assSum += m * m / (truthCount[pair.first] + hypCount[pair.second] - m);
    r.assA[a] = assSum / std::max(1.0, tp[a]);
    r.detA[a] = tp[a] / std::max(1.0, tp[a] + fn[a] + fp[a]);
    r.hota[a] = std::sqrt(r.detA[a] * r.assA[a]);
    r.locA[a] = tp[a] > 0 ? locSum[a] / tp[a] : 0.0;
  }
  return r;
}

}  // namespace fusedet::tracking
