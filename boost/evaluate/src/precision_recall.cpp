// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/precision_recall.h"

#include <algorithm>

namespace fusedet::boosting {

FrameOutcome frameOutcome(const std::vector<Detection>& detections, const StackMatch& match) {
  FrameOutcome f;
  f.positives = match.positives;
  for (std::size_t i = 0; i < detections.size() && i < match.detections.size(); ++i) {
    if (match.detections[i] == DetectionOutcome::kIgnored) continue;
    f.detections.push_back({detections[i].score, match.detections[i] == DetectionOutcome::kHit});
  }
  return f;
}

Counts countsOf(const std::vector<const FrameOutcome*>& frames) {
  Counts c;
  for (const FrameOutcome* f : frames) {
    ++c.stacks;
    c.positives += f->positives;
    std::size_t hits = 0;
    for (const auto& d : f->detections) hits += d.hit ? 1 : 0;
    c.hits += hits;
    c.falseAlarms += f->detections.size() - hits;
    c.misses += f->positives - hits;
  }
  return c;
}

std::vector<PrPoint> precisionRecallCurve(const std::vector<const FrameOutcome*>& frames) {
  std::vector<FrameOutcome::Scored> all;
  std::size_t positives = 0;
  for (const FrameOutcome* f : frames) {
    positives += f->positives;
    all.insert(all.end(), f->detections.begin(), f->detections.end());
  }
  std::sort(all.begin(), all.end(), [](const auto& a, const auto& b) { return a.score > b.score; });
  std::vector<PrPoint> curve;
  std::size_t hits = 0, fa = 0;
  for (std::size_t i = 0; i < all.size(); ++i) {
    (all[i].hit ? hits : fa) += 1;
    if (i + 1 < all.size() && all[i + 1].score == all[i].score) continue;  // ties enter together
    PrPoint p;
    p.threshold = all[i].score;
    p.hits = hits;
    p.falseAlarms = fa;
    p.recall = positives ? static_cast<double>(hits) / static_cast<double>(positives) : 0.0;
    p.precision = static_cast<double>(hits) / static_cast<double>(hits + fa);
    curve.push_back(p);
  }
  return curve;
}

std::optional<double> averagePrecision(const std::vector<PrPoint>& curve, std::size_t positives, ApRule rule) {
  if (positives == 0) return std::nullopt;
  const int n = rule == ApRule::kKitti40 ? 40 : 11;
  double sum = 0;
  for (int k = 0; k < n; ++k) {
    const double r = rule == ApRule::kKitti40 ? (k + 1) / 40.0 : k / 10.0;
    double best = 0;
    for (const PrPoint& p : curve)
      if (p.recall >= r - 1e-12) best = std::max(best, p.precision);
    sum += best;
  }
  return sum / n;
}

std::optional<double> averagePrecision(const std::vector<const FrameOutcome*>& frames, ApRule rule) {
  std::size_t positives = 0;
  for (const FrameOutcome* f : frames) positives += f->positives;
  return averagePrecision(precisionRecallCurve(frames), positives, rule);
}

std::vector<const FrameOutcome*> allFrames(const std::vector<FrameOutcome>& frames) {
  std::vector<const FrameOutcome*> p;
  p.reserve(frames.size());
  for (const FrameOutcome& f : frames) p.push_back(&f);
  return p;
}

}  // namespace fusedet::boosting
