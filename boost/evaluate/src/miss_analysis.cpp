// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/miss_analysis.h"

#include <algorithm>
#include <map>
#include <optional>
#include <stdexcept>
#include <tuple>

#include "fusedet/boost/grouping.h"
#include "fusedet/boost/integral_stack.h"
#include "fusedet/boost/laser_extent.h"
#include "fusedet/boost/window_scanner.h"

namespace fusedet::boosting {

namespace {

struct Bucket {
  const char* group;
  const char* name;
};
// Height limits follow KITTI's difficulty heights (25 / 40 px) and then double; aspect limits
// separate cars seen from behind (~1.2:1) from cars seen from the side (~2.5:1).
constexpr std::array<Bucket, 12> kBuckets{{{"height", "25-39 px"},
                                           {"height", "40-59 px"},
                                           {"height", "60-99 px"},
                                           {"height", ">= 100 px"},
                                           {"aspect", "w/h < 1.2"},
                                           {"aspect", "w/h 1.2-2"},
                                           {"aspect", "w/h >= 2"},
                                           {"occlusion", "occlusion 0"},
                                           {"occlusion", "occlusion 1"},
                                           {"occlusion", "occlusion >= 2"},
                                           {"truncation", "not truncated"},
                                           {"truncation", "truncated"}}};

std::size_t causeIndex(MissCause c) { return static_cast<std::size_t>(c); }

// What the scan offers for one object: its best window IoU, and the windows with IoU >= minIou.
struct Candidates {
  double bestIou = 0;
  std::vector<Box> windows;
};

Candidates candidatesFor(const Box& object, const std::vector<ScaleWindows>& scales, double minIou) {
  Candidates out;
  for (const ScaleWindows& s : scales) {
    // Windows that do not intersect the object have IoU 0: only the positions that overlap it.
    const auto xFrom = std::lower_bound(s.xs.begin(), s.xs.end(), object.x - s.winW);
    const auto yFrom = std::lower_bound(s.ys.begin(), s.ys.end(), object.y - s.winH);
    for (auto y = yFrom; y != s.ys.end() && *y < object.bottom(); ++y)
      for (auto x = xFrom; x != s.xs.end() && *x < object.right(); ++x) {
        const Box w{double(*x), double(*y), double(s.winW), double(s.winH)};
        const double o = iou(w, object);
        out.bestIou = std::max(out.bestIou, o);
        if (o >= minIou) out.windows.push_back(w);
      }
  }
  return out;
}

PositiveOutcome outcomeOf(std::size_t l, const Label& label) {
  PositiveOutcome p;
  p.label = l;
  p.box = label.box;
  p.truncation = label.truncation;
  p.occlusion = label.occlusion;
  return p;
}

}  // namespace

std::string missCauseName(MissCause cause) {
  switch (cause) {
    case MissCause::kScanGeometry: return "scan geometry";
    case MissCause::kCascade: return "cascade";
    case MissCause::kGrouping: return "grouping";
    case MissCause::kLocalisation: return "localisation";
    case MissCause::kUntrained: return "untrained fold";
  }
  return "?";
}

std::string groupingLossName(GroupingLoss loss) {
  switch (loss) {
    case GroupingLoss::kNone: return "none";
    case GroupingLoss::kTakenElsewhere: return "its detection matched elsewhere";
    case GroupingLoss::kMergedOffTarget: return "merged into a detection that misses the object";
    case GroupingLoss::kInsideBiggerGroup: return "group inside a bigger group";
    case GroupingLoss::kTooFewNeighbours: return "too few neighbours";
  }
  return "?";
}

FrameMissAnalysis analyseMisses(const Detector& detector, const LayerStack& stack, const Labels& labels,
                                const MatchConfig& match, const DetectionSetup& setup,
                                const MissAnalysisConfig& config) {
  const Cascade& cascade = detector.cascade();
  if (cascade.isOpenCv()) throw std::invalid_argument("analyseMisses: " + cascade.source + " is an OpenCV cascade");
  FrameMissAnalysis out;
  // Detections as detectChain().
  const std::vector<RawHit> hits = detector.scan(stack, setup.scan);
  std::vector<HitFate> fates;
  out.detections = groupHits(hits, setup.group, cascade.className, stack, &fates);
  refineToLaserExtent(out.detections, stack, setup.laserExtent);
  out.match = matchDetections(out.detections, labels, match);

  std::map<std::tuple<double, double, double, double>, std::size_t> hitAt;  // window -> raw hit
  for (std::size_t i = 0; i < hits.size(); ++i)
    hitAt.emplace(std::make_tuple(hits[i].box.x, hits[i].box.y, hits[i].box.w, hits[i].box.h), i);
  const std::vector<ScaleWindows> scales = windowScales(cascade, stack.width(), stack.height(), setup.scan);
  std::optional<IntegralStack> integrals;  // built on the first miss only
  const int stageCount = static_cast<int>(cascade.stages.size());

  for (std::size_t l = 0; l < labels.size(); ++l) {
    if (out.match.labelRoles[l] != LabelRole::kPositive) continue;
    PositiveOutcome p = outcomeOf(l, labels[l]);
    p.hit = out.match.hitBy[l] >= 0;
    p.stageCount = stageCount;
    if (p.hit) {
      out.positives.push_back(p);
      continue;
    }
    for (const Detection& d : out.detections)
      if ((d.className.empty() || d.className == match.className) && d.box.h >= match.minDetectionHeight)
        p.bestDetectionIou = std::max(p.bestDetectionIou, iou(d.box, p.box));
    bool taken = false, merged = false, inside = false;
    const Candidates cand = candidatesFor(p.box, scales, match.minIou);
    p.bestWindowIou = cand.bestIou;
    p.candidates = cand.windows.size();
    if (!integrals && !cand.windows.empty()) integrals.emplace(integrateFor(cascade, stack));
    for (const Box& w : cand.windows) {
      const WindowResult r = evaluateWindow(cascade, *integrals, w);
      p.deepestStage = std::max(p.deepestStage, r.stagesPassed);
      if (!r.accepted) continue;
      const auto it = hitAt.find(std::make_tuple(w.x, w.y, w.w, w.h));
      if (it == hitAt.end())
        throw std::logic_error("analyseMisses: a window evaluateWindow() accepts is not among the scan's hits");
      ++p.acceptedCandidates;
      const HitFate& f = fates[it->second];
      p.largestGroup = std::max(p.largestGroup, f.groupSize);
      if (f.detection >= 0) {
        const Box& db = out.detections[static_cast<std::size_t>(f.detection)].box;
        (iou(db, p.box) >= match.minIou ? taken : merged) = true;
      }
      inside = inside || f.outcome == HitFate::Outcome::kInsideBiggerGroup;
    }
    if (p.bestWindowIou < match.minIou) {
      p.cause = MissCause::kScanGeometry;
    } else if (p.acceptedCandidates > 0) {
      p.cause = MissCause::kGrouping;
      p.groupingLoss = taken    ? GroupingLoss::kTakenElsewhere
                       : merged ? GroupingLoss::kMergedOffTarget
                       : inside ? GroupingLoss::kInsideBiggerGroup
                                : GroupingLoss::kTooFewNeighbours;
    } else if (p.bestDetectionIou >= config.localisationIou) {
      p.cause = MissCause::kLocalisation;
    } else {
      p.cause = MissCause::kCascade;
    }
    out.positives.push_back(p);
  }
  return out;
}

std::vector<PositiveOutcome> untrainedOutcomes(const Labels& labels, const MatchConfig& match) {
  std::vector<PositiveOutcome> out;
  for (std::size_t l = 0; l < labels.size(); ++l)
    if (labelRole(labels[l], match) == LabelRole::kPositive) {
      PositiveOutcome p = outcomeOf(l, labels[l]);
      p.cause = MissCause::kUntrained;
      out.push_back(p);
    }
  return out;
}

std::vector<std::size_t> objectBuckets(const Box& box, int occlusion, double truncation) {
  const double h = box.h, aspect = box.h > 0 ? box.w / box.h : 0;
  const std::size_t height = h < 40 ? 0 : h < 60 ? 1 : h < 100 ? 2 : 3;
  const std::size_t shape = aspect < 1.2 ? 4 : aspect < 2 ? 5 : 6;
  const std::size_t occl = occlusion <= 0 ? 7 : occlusion == 1 ? 8 : 9;
  const std::size_t trunc = truncation > 0 ? 11 : 10;
  return {height, shape, occl, trunc};
}

MissBreakdown summariseMisses(const std::vector<std::vector<PositiveOutcome>>& frames,
                              const MissAnalysisConfig& config) {
  MissBreakdown b;
  for (const Bucket& k : kBuckets) {
    b.bucketGroup.emplace_back(k.group);
    b.bucketNames.emplace_back(k.name);
  }
  b.positives.assign(kBuckets.size(), 0);
  b.misses.assign(kBuckets.size(), 0);
  for (auto& row : b.byCause) row.assign(kBuckets.size(), 0);
  for (const auto& frame : frames)
    for (const PositiveOutcome& p : frame) {
      const std::vector<std::size_t> buckets = objectBuckets(p.box, p.occlusion, p.truncation);
      ++b.allPositives;
      for (std::size_t k : buckets) ++b.positives[k];
      if (p.hit) continue;
      ++b.allMisses;
      const std::size_t c = causeIndex(p.cause);
      ++b.total[c];
      if (p.bestDetectionIou >= config.localisationIou) ++b.nearDetection[c];
      for (std::size_t k : buckets) {
        ++b.misses[k];
        ++b.byCause[c][k];
      }
      if (p.cause == MissCause::kGrouping) ++b.groupingLosses[static_cast<std::size_t>(p.groupingLoss)];
      if (p.groupingLoss == GroupingLoss::kTooFewNeighbours) {
        const auto g = static_cast<std::size_t>(p.largestGroup);
        if (b.tooFewByGroupSize.size() <= g) b.tooFewByGroupSize.resize(g + 1, 0);
        ++b.tooFewByGroupSize[g];
      }
      if (p.cause == MissCause::kCascade) {
        const auto s = static_cast<std::size_t>(p.deepestStage);
        if (b.rejectedAtStage.size() <= s) b.rejectedAtStage.resize(s + 1, 0);
        ++b.rejectedAtStage[s];
      }
    }
  return b;
}

}  // namespace fusedet::boosting
