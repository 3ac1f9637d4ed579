// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/gentle_boost.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusedet::boosting {

double stageThreshold(std::vector<double> scores, double minHit) {
  if (scores.empty()) return 0;
  std::sort(scores.begin(), scores.end());
  const auto n = static_cast<double>(scores.size());
  // May drop at most floor((1 - minHit) * n) positives (with a tolerance for 0.995 * 200 etc.).
  const auto drop = static_cast<std::size_t>(std::floor((1.0 - minHit) * n + 1e-9));
  const double t = scores[std::min(drop, scores.size() - 1)];
  return t - 1e-9 * std::max(1.0, std::fabs(t));
}

StageResult boostStage(std::size_t n, std::size_t positives, const StumpFinder& find,
                       const StageConfig& config, const std::function<void(const RoundInfo&)>& onRound) {
  if (positives == 0 || positives >= n)
    throw std::invalid_argument("trainStage: need positives and negatives (" +
                                std::to_string(positives) + " of " + std::to_string(n) + " samples)");
  // Each class starts with half the weight, so the first stump is not dominated by the larger set.
  std::vector<double> w(n);
  for (std::size_t i = 0; i < n; ++i)
    w[i] = i < positives ? 0.5 / double(positives) : 0.5 / double(n - positives);
  std::vector<float> wf(n), values(n);
  std::vector<double> score(n, 0.0);
  StageResult result;
  for (int round = 1; round <= config.maxWeak; ++round) {
    for (std::size_t i = 0; i < n; ++i) wf[i] = static_cast<float>(w[i]);
    const FittedStump s = find(wf, values);
    result.stumps.push_back(s);
    double sum = 0;
    for (std::size_t i = 0; i < n; ++i) {
      const double f = s(values[i]);
      score[i] += f;
      const double y = i < positives ? 1.0 : -1.0;
      w[i] *= std::exp(-y * f);
      sum += w[i];
    }
    for (double& v : w) v /= sum;
    result.threshold =
        stageThreshold(std::vector<double>(score.begin(), score.begin() + static_cast<std::ptrdiff_t>(positives)),
                       config.minHit);
    std::size_t hits = 0, fas = 0;
    for (std::size_t i = 0; i < n; ++i)
      if (score[i] >= result.threshold) (i < positives ? hits : fas)++;
    result.hitRate = double(hits) / double(positives);
    result.falseAlarm = double(fas) / double(n - positives);
    if (onRound) {
      RoundInfo info;
      info.stump = s;
      info.round = round;
      info.hitRate = result.hitRate;
      info.falseAlarm = result.falseAlarm;
      info.threshold = result.threshold;
      onRound(info);
    }
    if (result.falseAlarm <= config.maxFalseAlarm) {
      result.reachedFalseAlarm = true;
      break;
    }
  }
  return result;
}

StageResult trainStage(const FeatureMatrix& m, std::size_t positives,
                       const FeatureValuesFn& rawValues, const StageConfig& config,
                       const std::function<void(const RoundInfo&)>& onRound) {
  StumpSearchOptions search;
  search.threads = config.threads;
  search.refineTop = config.refineTop;
  return boostStage(
      m.samples(), positives,
      [&](std::span<const float> weights, std::span<float> chosen) {
        const FittedStump s = findBestStump(m, positives, weights, rawValues, search);
        rawValues(s.feature, chosen);
        return s;
      },
      config, onRound);
}

}  // namespace fusedet::boosting
