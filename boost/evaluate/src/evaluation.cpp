// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/evaluation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>

#include "fusedet/core/box.h"

namespace fusedet::boosting {
namespace {

bool contains(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

}  // namespace

LabelRole labelRole(const Label& label, const MatchConfig& config) {
  const auto listed = [&](const std::vector<std::string>& names) {
    return contains(names, label.className) || contains(names, label.sourceClass);
  };
  if (listed(config.ignoreClasses)) return LabelRole::kIgnoreRegion;
  if (!label.ignore && (label.className == config.className || contains(config.aliasClasses, label.className))) {
    const bool tooSmall = label.box.h < config.minHeight;
    const bool tooOccluded = label.occlusion > config.maxOcclusion;
    const bool tooTruncated = config.maxTruncation >= 0 && label.truncation > config.maxTruncation;
    return (tooSmall || tooOccluded || tooTruncated) ? LabelRole::kIgnoredLabel : LabelRole::kPositive;
  }
  if (listed(config.neighbourClasses)) return LabelRole::kIgnoredLabel;
  if (label.ignore && !contains(config.falseAlarmClasses, label.sourceClass)) return LabelRole::kIgnoreRegion;
  return LabelRole::kBackground;
}

StackMatch matchDetections(const std::vector<Detection>& detections, const Labels& labels,
                           const MatchConfig& config) {
  StackMatch m;
  m.detections.assign(detections.size(), DetectionOutcome::kIgnored);
  m.labelRoles.reserve(labels.size());
  for (const Label& l : labels) {
    m.labelRoles.push_back(labelRole(l, config));
    if (m.labelRoles.back() == LabelRole::kPositive) ++m.positives;
  }
  m.hitBy.assign(labels.size(), -1);

  // Highest score first; ties by index, so the result does not depend on the sort's stability.
  std::vector<std::size_t> order(detections.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    if (detections[a].score != detections[b].score) return detections[a].score > detections[b].score;
    return a < b;
  });

  for (std::size_t d : order) {
    const Detection& det = detections[d];
    if (!det.className.empty() && det.className != config.className) continue;  // stays kIgnored
    if (det.box.h < config.minDetectionHeight) {  // the devkit ignores detections below 25 px
      ++m.ignored;
      continue;
    }
    // 1. the best free positive
    int best = -1;
    double bestIou = 0;
    for (std::size_t l = 0; l < labels.size(); ++l) {
      if (m.labelRoles[l] != LabelRole::kPositive || m.hitBy[l] >= 0) continue;
      const double o = iou(det.box, labels[l].box);
      if (o >= config.minIou && o > bestIou) {
        bestIou = o;
        best = static_cast<int>(l);
      }
    }
    if (best >= 0) {
      m.hitBy[static_cast<std::size_t>(best)] = static_cast<int>(d);
      m.detections[d] = DetectionOutcome::kHit;
      ++m.hits;
      continue;
    }
    // 2. an ignored label of the class, or an ignore region holding the detection
    bool absorbed = false;
    for (std::size_t l = 0; l < labels.size() && !absorbed; ++l) {
      if (m.labelRoles[l] == LabelRole::kIgnoredLabel)
        absorbed = iou(det.box, labels[l].box) >= config.minIou;
      else if (m.labelRoles[l] == LabelRole::kIgnoreRegion)
        absorbed = coverage(det.box, labels[l].box) >= config.minIou;
    }
    if (absorbed) {
      ++m.ignored;
      continue;
    }
    // 3. anything else, including a second detection on a positive already hit
    m.detections[d] = DetectionOutcome::kFalseAlarm;
    ++m.falseAlarms;
  }
  m.misses = m.positives - m.hits;
  return m;
}

void Counts::add(const StackMatch& m) {
  hits += m.hits;
  falseAlarms += m.falseAlarms;
  misses += m.misses;
  ignored += m.ignored;
  positives += m.positives;
  ++stacks;
}

std::optional<double> Counts::recall() const {
  if (positives == 0) return std::nullopt;
  return static_cast<double>(hits) / static_cast<double>(positives);
}

std::optional<double> Counts::precision() const {
  const std::size_t detected = hits + falseAlarms;
  if (detected == 0) return std::nullopt;
  return static_cast<double>(hits) / static_cast<double>(detected);
}

double fMeasure(double recall, double precision) {
  return recall + precision > 0 ? 2 * recall * precision / (recall + precision) : 0.0;
}

std::optional<double> Counts::fMeasure() const {
  const auto r = recall();
  if (!r) return std::nullopt;
  const auto p = precision();
  return p ? boosting::fMeasure(*r, *p) : 0.0;  // no detection: recall 0, F 0
}

std::string formatMeasure(const std::optional<double>& value, int decimals) {
  if (!value) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, *value);
  return buf;
}

namespace {

void computeShares(CascadeSummary& s) {
  double total = 0;
  for (const auto& [layer, w] : s.layerWeight) total += w;
  s.layerWeightShare.clear();
  for (const auto& [layer, w] : s.layerWeight) s.layerWeightShare[layer] = total > 0 ? w / total : 0.0;
}

}  // namespace

CascadeSummary summarizeCascade(const Cascade& cascade) {
  CascadeSummary s;
  s.stages = cascade.stages.size();
  for (const std::string& l : cascade.layers) s.layerWeight[l] = 0;  // listed even when unused
  // One split on `feature` moving the sum by `weight`.
  auto addSplit = [&](int feature, double weight) {
    ++s.splits;
    std::string layerName = cascade.layers.empty() ? std::string("?") : cascade.layers.front();
    if (!cascade.isOpenCv()) {
      const Feature& f = cascade.features.at(static_cast<std::size_t>(feature));
      layerName = cascade.layers.at(static_cast<std::size_t>(f.layer));
      if (isCorner(f.type)) ++s.cornerCount;
    }
    s.layerWeight[layerName] += weight;
    ++s.layerCount[layerName];
  };
  for (const Stage& stage : cascade.stages) {
    for (const Stump& stump : stage.stumps) {
      ++s.length;
      addSplit(stump.feature, std::abs(stump.right - stump.left));
    }
  }
  for (const auto& trees : cascade.treeStages)
    for (const Tree& t : trees) {
      ++s.length;
      // Leaves below each node (children follow their parent: from the last node backwards).
      std::vector<std::pair<double, double>> range(t.nodes.size());
      auto rangeOf = [&](int child) {
        if (child > 0) return range[static_cast<std::size_t>(child)];
        const double v = t.leaves[static_cast<std::size_t>(-child)];
        return std::pair{v, v};
      };
      for (std::size_t n = t.nodes.size(); n-- > 0;) {
        const auto l = rangeOf(t.nodes[n].left), r = rangeOf(t.nodes[n].right);
        range[n] = {std::min(l.first, r.first), std::max(l.second, r.second)};
      }
      for (std::size_t n = 0; n < t.nodes.size(); ++n) addSplit(t.nodes[n].feature, range[n].second - range[n].first);
    }
  computeShares(s);
  return s;
}

CascadeSummary combineSummaries(const std::vector<CascadeSummary>& parts) {
  CascadeSummary s;
  for (const CascadeSummary& p : parts) {
    s.length += p.length;
    s.splits += p.splits;
    s.stages += p.stages;
    s.cornerCount += p.cornerCount;
    for (const auto& [l, w] : p.layerWeight) s.layerWeight[l] += w;
    for (const auto& [l, n] : p.layerCount) s.layerCount[l] += n;
  }
  computeShares(s);
  return s;
}

}  // namespace fusedet::boosting
