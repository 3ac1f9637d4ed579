// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where a missed object is lost: for every positive (evaluation.h's roles) that no detection hits,
// which step of detection lost it, in this order of precedence:
//  - kScanGeometry: no window the scan visits (sizes from the minimum size by the scale factor at
//    the model's aspect ratio, positions by the scaled step: windowScales()) reaches IoU >= minIou
//    with it - the scan's ceiling, whatever the cascade says;
//  - kGrouping: some such window ("candidate") is accepted by the cascade, but grouping loses it:
//    its group is too small (<= min neighbours), lies inside a bigger group, is merged into a
//    detection whose box misses the object (IoU < minIou), or its detection is matched elsewhere;
//    (minIou is the class's hit overlap, MatchConfig: 0.7 for car, 0.5 for person and bike)
//  - kLocalisation: no candidate is accepted, but a detection overlaps the object with
//    localisationIou <= IoU < minIou (detected, badly placed: counted as a false alarm too);
//  - kCascade: every candidate is rejected by the cascade; `deepestStage` says how far the best
//    one came (it was rejected by stage deepestStage + 1, counted from 1);
//  - kUntrained: the fold's cascade could not be trained (cross_validation.h).
// The per-window decisions are evaluateWindow()'s, which the scanner's equal (tested), so the
// analysis' detections are exactly those of detectChain() for one cascade.

#include <array>
#include <cstddef>
#include <string>
#include <vector>

#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/core/label.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

enum class MissCause { kScanGeometry, kCascade, kGrouping, kLocalisation, kUntrained };
inline constexpr std::array<MissCause, 5> kMissCauses{MissCause::kScanGeometry, MissCause::kCascade,
                                                      MissCause::kGrouping, MissCause::kLocalisation,
                                                      MissCause::kUntrained};
std::string missCauseName(MissCause cause);  // "scan geometry", "cascade", ...

// Why grouping lost an accepted candidate (kGrouping only), in order of precedence.
enum class GroupingLoss { kNone, kTakenElsewhere, kMergedOffTarget, kInsideBiggerGroup, kTooFewNeighbours };
std::string groupingLossName(GroupingLoss loss);

struct MissAnalysisConfig {
  double localisationIou = 0.3;  // a detection at least this close counts as "detected, badly placed"
};

// One positive of a stack and what became of it.
struct PositiveOutcome {
  std::size_t label = 0;  // index into the stack's labels
  Box box;
  double truncation = 0;
  int occlusion = 0;
  bool hit = false;
  // The rest describes a miss (hit == false).
  MissCause cause = MissCause::kCascade;
  double bestWindowIou = 0;         // best IoU of any scanned window
  std::size_t candidates = 0;       // scanned windows with IoU >= minIou
  std::size_t acceptedCandidates = 0;
  int deepestStage = 0;             // most stages a candidate passed (== stageCount when accepted)
  int stageCount = 0;               // stages of the cascade
  GroupingLoss groupingLoss = GroupingLoss::kNone;
  int largestGroup = 0;             // most members of a group an accepted candidate fell in
  double bestDetectionIou = 0;      // best IoU of a counted detection (height >= minDetectionHeight)
};

struct FrameMissAnalysis {
  std::vector<Detection> detections;  // = detectChain({&detector}, stack, setup)
  StackMatch match;                   // = matchDetections(detections, labels, match)
  std::vector<PositiveOutcome> positives;
};

// Detects with one cascade (our models; OpenCV models are refused) and explains every miss.
FrameMissAnalysis analyseMisses(const Detector& detector, const LayerStack& stack, const Labels& labels,
                                const MatchConfig& match, const DetectionSetup& setup,
                                const MissAnalysisConfig& config = {});

// The positives of a stack no cascade ran on (an untrained fold): every one missed, kUntrained.
std::vector<PositiveOutcome> untrainedOutcomes(const Labels& labels, const MatchConfig& match);

// Counts of positives and misses per cause, overall and per object bucket.
struct MissBreakdown {
  // Buckets an object falls in (one per group): box height, aspect (width / height), occlusion
  // level, truncation. bucketGroup[b] names the group of bucket b.
  std::vector<std::string> bucketNames, bucketGroup;
  std::vector<std::size_t> positives, misses;                          // per bucket
  std::array<std::vector<std::size_t>, kMissCauses.size()> byCause;    // [cause][bucket]
  std::array<std::size_t, kMissCauses.size()> total{};                 // misses per cause
  std::array<std::size_t, kMissCauses.size()> nearDetection{};         // ... with a detection at IoU >= localisationIou
  std::array<std::size_t, 5> groupingLosses{};                         // per GroupingLoss (kGrouping misses)
  std::vector<std::size_t> rejectedAtStage;                            // kCascade: [s] = rejected by stage s + 1
  std::vector<std::size_t> tooFewByGroupSize;  // kTooFewNeighbours: [g] = largest group had g members
  std::size_t allPositives = 0, allMisses = 0;
};

// Buckets of one object (indices into MissBreakdown's bucket lists).
std::vector<std::size_t> objectBuckets(const Box& box, int occlusion, double truncation);

MissBreakdown summariseMisses(const std::vector<std::vector<PositiveOutcome>>& frames,
                              const MissAnalysisConfig& config = {});

}  // namespace fusedet::boosting
