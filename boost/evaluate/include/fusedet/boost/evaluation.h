// SPDX-License-Identifier: Apache-2.0
#pragma once
// Evaluation of detections against labels (paper §4, design.md §5) with the KITTI object devkit's
// 2D rules (cpp/evaluate_object.cpp), "moderate" difficulty by default:
//  - a positive is a label of the evaluated class (or of an alias) with box height >= minHeight
//    (25 px), occlusion <= maxOcclusion (1) and truncation <= maxTruncation (0.3). KITTI
//    *tracking* labels hold a truncation level (0, 1, 2) instead of a fraction: the same numeric
//    test keeps level 0 and drops levels 1 and 2 (a partly truncated object's fraction is unknown,
//    so it is not counted either way rather than guessed);
//  - a label of the class that fails these limits, or a label of the neighbouring class (KITTI:
//    Van for Car, Person_sitting for Pedestrian; `neighbourClasses`), is an "ignored label": a
//    detection with IoU >= minIou on it is neither a hit nor a false alarm, missing it is no miss;
//  - an ignore region (DontCare: a Label::ignore label whose source class is not one of
//    `falseAlarmClasses`, or a class in `ignoreClasses`) absorbs a detection whose area lies
//    inside it by >= minIou (intersection / detection area, as the devkit);
//  - every other label (Truck, Tram, Misc, other project classes) is background: a detection on
//    it is a false alarm;
//  - detections lower than minDetectionHeight (25 px) are ignored, as the devkit does.
// Matching is greedy in descending score order; each positive is hit at most once, so a second
// detection on the same object is a false alarm. Because higher scores are matched first, the
// matching of the detections above any score threshold is a prefix of this one: one pass gives
// the whole precision-recall curve (precision_recall.h).

#include <cstddef>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/label.h"

namespace fusedet::boosting {

struct MatchConfig {
  std::string className;                      // the evaluated class ("car", "person", "bike", ...)
  std::vector<std::string> aliasClasses;      // also count as positives (e.g. {"van"} for car)
  std::vector<std::string> neighbourClasses;  // ignored labels, by class or source class (KITTI)
  std::vector<std::string> ignoreClasses;     // also treated as ignore regions (coverage rule)
  // Source classes of Label::ignore labels that are objects, not regions: false alarms.
  std::vector<std::string> falseAlarmClasses = {"Truck", "Tram", "Misc", "Person_sitting"};
  double minIou = 0.5;              // hit: IoU(detection, label) >= minIou
  double minHeight = 25;            // pixels; lower labels are ignored labels (KITTI moderate)
  int maxOcclusion = 1;             // KITTI level; more occluded labels are ignored labels
  double maxTruncation = 0.3;       // fraction (object labels) or level (tracking); < 0: not checked
  double minDetectionHeight = 25;   // pixels; lower detections are ignored (KITTI devkit)
};

// What happened to each detection and label of one stack.
enum class DetectionOutcome { kHit, kFalseAlarm, kIgnored };
enum class LabelRole { kPositive, kIgnoredLabel, kIgnoreRegion, kBackground };

struct StackMatch {
  std::vector<DetectionOutcome> detections;  // parallel to the detections passed in
  std::vector<LabelRole> labelRoles;         // parallel to the labels passed in
  std::vector<int> hitBy;                    // per label: index of the detection that hit it, or -1
  std::size_t hits = 0, falseAlarms = 0, ignored = 0, positives = 0, misses = 0;
};

// The role a label plays when evaluating `config.className`.
LabelRole labelRole(const Label& label, const MatchConfig& config);

// Matches the detections of one stack (any order; only those of config.className or without a
// class name are considered, others are reported kIgnored) against its labels.
StackMatch matchDetections(const std::vector<Detection>& detections, const Labels& labels,
                           const MatchConfig& config);

// Harmonic mean of recall and precision; 0 when both are 0.
double fMeasure(double recall, double precision);

// Counts over a test set and the measures derived from them.
struct Counts {
  std::size_t hits = 0, falseAlarms = 0, misses = 0, ignored = 0, positives = 0, stacks = 0;

  void add(const StackMatch& m);
  // hits / positives; undefined (nullopt) when there is nothing to find.
  std::optional<double> recall() const;
  // hits / (hits + false alarms); undefined (nullopt) when nothing was detected, never 1.
  std::optional<double> precision() const;
  // Harmonic mean; undefined without positives. With positives and no detection it is 0 (recall 0:
  // F tends to 0 for any precision).
  std::optional<double> fMeasure() const;
};

// "0.583" or "null" (for reports and JSON-like text).
std::string formatMeasure(const std::optional<double>& value, int decimals = 2);

// What a cascade is made of (paper §4, Fig. 7). The weight of a stump is |right - left|, the
// amount it moves the stage sum between its two sides; its mean (left + right) / 2 is a constant
// that only shifts the stage threshold, so it says nothing about what the layer contributes.
// Gentle AdaBoost has no per-round alpha: the leaves are the weighted means themselves. A tree's
// split node weighs what a stump there would: max - min of the leaves below it (a node above two
// leaves: |right - left|).
struct CascadeSummary {
  std::size_t length = 0;  // weak classifiers (stumps or trees) over all stages
  std::size_t splits = 0;  // split nodes (= length for stumps)
  std::size_t stages = 0;
  std::map<std::string, double> layerWeight;       // layer -> summed split weight
  std::map<std::string, double> layerWeightShare;  // layer -> weight / total weight (sums to 1)
  std::map<std::string, std::size_t> layerCount;   // layer -> split nodes on it
  std::size_t cornerCount = 0;                     // split nodes on corner-like features (g-j)
  double cornerShare() const { return splits ? double(cornerCount) / double(splits) : 0.0; }
};

// Summary of one cascade. Imported OpenCV models have one layer and no corner features.
CascadeSummary summarizeCascade(const Cascade& cascade);
// Summary of several cascades used together (the AND combination): lengths, stages, weights and
// counts add up; shares are recomputed over the sum.
CascadeSummary combineSummaries(const std::vector<CascadeSummary>& parts);

}  // namespace fusedet::boosting
