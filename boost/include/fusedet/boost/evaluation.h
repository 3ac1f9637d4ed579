#pragma once
// Evaluation of detections against labels (paper §4, design.md §5): matching by IoU, recall,
// precision, F-measure. Which labels count follows KITTI's "moderate" protocol by default:
//  - a positive is a label of the evaluated class (or of an alias, e.g. "van" for "car" when
//    configured), not marked ignore, box height >= minHeight and occlusion <= maxOcclusion
//    (and truncation <= maxTruncation when that is set);
//  - a label of the evaluated class that fails the difficulty limits is an "ignored label": a
//    detection with IoU >= minIou on it is neither a hit nor a false alarm;
//  - an ignore region (Label::ignore, e.g. DontCare, Truck, Tram, Misc, Person_sitting, or a class
//    listed in ignoreClasses) absorbs a detection whose area lies inside it by >= minIou
//    (KITTI's DontCare rule: intersection / detection area);
//  - labels of any other class (e.g. "van" for "car" by default) are ordinary background: a
//    detection on them is a false alarm (a hard negative).
// Matching is greedy in descending score order; each positive is hit at most once, so a second
// detection on the same object is a false alarm.

#include <cstddef>
#include <map>
#include <string>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/label.h"

namespace fusedet::boosting {

struct MatchConfig {
  std::string className;                 // the evaluated class ("car", "person", "bike", ...)
  std::vector<std::string> aliasClasses;   // also count as positives (e.g. {"van"} for car)
  std::vector<std::string> ignoreClasses;  // also treated as ignore regions (e.g. {"van"})
  double minIou = 0.5;                   // hit: IoU(detection, label) >= minIou
  double minHeight = 25;                 // pixels; lower labels are ignored labels (KITTI moderate)
  int maxOcclusion = 1;                  // KITTI level; more occluded labels are ignored labels
  double maxTruncation = -1;             // < 0: truncation not checked (tracking labels are levels)
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
  // hits / positives; 1 when there is nothing to find (vacuous).
  double recall() const;
  // hits / (hits + false alarms); 1 when nothing was detected (no false alarm was made).
  double precision() const;
  // Harmonic mean of recall and precision; 0 when both are 0.
  double fMeasure() const;
};

// What a cascade is made of (paper §4, Fig. 7). The weight of a stump is |right - left|, the
// amount it moves the stage sum between its two sides; its mean (left + right) / 2 is a constant
// that only shifts the stage threshold, so it says nothing about what the layer contributes.
// Gentle AdaBoost has no per-round alpha: the leaves are the weighted means themselves.
struct CascadeSummary {
  std::size_t length = 0;  // weak classifiers (stumps) over all stages
  std::size_t stages = 0;
  std::map<std::string, double> layerWeight;       // layer -> summed stump weight
  std::map<std::string, double> layerWeightShare;  // layer -> weight / total weight (sums to 1)
  std::map<std::string, std::size_t> layerCount;   // layer -> stumps on it
  std::size_t cornerCount = 0;                     // stumps on corner-like features (g-j)
  double cornerShare() const { return length ? double(cornerCount) / double(length) : 0.0; }
};

// Summary of one cascade. Imported OpenCV models have one layer and no corner features.
CascadeSummary summarizeCascade(const Cascade& cascade);
// Summary of several cascades used together (the AND combination): lengths, stages, weights and
// counts add up; shares are recomputed over the sum.
CascadeSummary combineSummaries(const std::vector<CascadeSummary>& parts);

}  // namespace fusedet::boosting
