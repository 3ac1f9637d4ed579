// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/bootstrap.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>

namespace fusedet::boosting {
namespace {

// Linear interpolation between order statistics (type 7, R's default).
double quantile(const std::vector<double>& sorted, double q) {
  const double pos = q * static_cast<double>(sorted.size() - 1);
  const auto lo = static_cast<std::size_t>(std::floor(pos));
  const std::size_t hi = std::min(lo + 1, sorted.size() - 1);
  return sorted[lo] + (pos - static_cast<double>(lo)) * (sorted[hi] - sorted[lo]);
}

std::vector<const FrameOutcome*> select(const std::vector<FrameOutcome>& frames,
                                        const std::vector<std::size_t>& indices) {
  std::vector<const FrameOutcome*> p;
  p.reserve(indices.size());
  for (std::size_t i : indices) p.push_back(&frames.at(i));
  return p;
}

}  // namespace

std::optional<Interval> bootstrapInterval(std::size_t frames, const FrameMeasure& measure,
                                          const BootstrapConfig& config) {
  if (frames == 0 || config.resamples == 0) return std::nullopt;
  std::mt19937_64 rng(config.seed);
  std::vector<double> values;
  values.reserve(config.resamples);
  std::vector<std::size_t> idx(frames);
  for (std::size_t r = 0; r < config.resamples; ++r) {
    for (std::size_t& i : idx) i = static_cast<std::size_t>(rng() % frames);
    if (const auto v = measure(idx)) values.push_back(*v);
  }
  if (values.empty()) return std::nullopt;
  std::sort(values.begin(), values.end());
  const double tail = (1 - config.level) / 2;
  return Interval{quantile(values, tail), quantile(values, 1 - tail), values.size()};
}

std::optional<double> fMeasureOf(const std::vector<FrameOutcome>& frames, const std::vector<std::size_t>& indices) {
  return countsOf(select(frames, indices)).fMeasure();
}

std::optional<double> averagePrecisionOf(const std::vector<FrameOutcome>& frames,
                                         const std::vector<std::size_t>& indices, ApRule rule) {
  return averagePrecision(select(frames, indices), rule);
}

std::string verdict(const std::optional<Interval>& difference) {
  if (!difference) return "not shown";
  if (difference->lo > 0) return "holds";
  if (difference->hi < 0) return "contradicted";
  return "not shown";
}

}  // namespace fusedet::boosting
