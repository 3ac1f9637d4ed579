// SPDX-License-Identifier: Apache-2.0
#pragma once
// Training samples (paper §4): positives from the labelled boxes of one class (optionally also
// from horizontally flipped copies of their stacks), negatives bootstrapped for every new stage
// from windows of the training stacks that no label of the class overlaps (IoU < 0.3; windows
// lying in ignore regions such as KITTI DontCare are skipped) and from clutter stacks (stacks
// without the class), keeping only windows the current cascade still accepts.
//
// Samples are windows on integral stacks held here; features are evaluated on the stack itself,
// exactly as the detector does (feature.h's pixel rule), so training sees what detection sees.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/integral_stack.h"
#include "fusedet/core/dataset.h"

namespace fusedet::boosting {

struct SampleConfig {
  std::string className = "car";
  // Labels of the class that become positives (KITTI "moderate" by default).
  double minPositiveHeight = 25;  // reference pixels
  int maxOcclusion = 1;
  // A window is a negative candidate when IoU < maxNegativeIou with every positive of the class
  // and it overlaps no ignored label by more than maxIgnoreCoverage of the window's area or of the
  // label's area. Ignored labels: ignore regions (DontCare, ...), labels of the class that are not
  // positives (too small, too occluded) and labels of `ignoreClasses`; evaluation neither counts
  // a detection on them as a hit nor as a false alarm, so a window holding most of one (even a
  // window 2-3x larger than the object) must not be taught as background.
  double maxNegativeIou = 0.3;
  double maxIgnoreCoverage = 0.5;
  std::vector<std::string> ignoreClasses;  // e.g. {"van"} for car: KITTI's neighbouring class
  int baseWindowHeight = 24;  // model window height in pixels; width from the positives' aspect
  ScanParams scan;            // windows scanned for negatives (scales, step)
};

struct Sample {
  std::uint32_t stack = 0;  // index into TrainingStacks
  Box window;               // reference pixels of that stack
};

// Does `label` become a positive of `config.className`?
bool isPositiveLabel(const Label& label, const SampleConfig& config);
// Is `label` neither a positive nor background for config.className (see SampleConfig)?
bool isIgnoredLabel(const Label& label, const SampleConfig& config);
// The classes KITTI's devkit ignores next to `className` ("van" for "car"); empty for others.
std::vector<std::string> neighbourClasses(const std::string& className);
// May `window` of a stack with `labels` serve as a negative?
bool isNegativeWindow(const Box& window, const Labels& labels, const SampleConfig& config);

// isNegativeWindow() for many windows of one stack: the labels sorted once into ignored labels
// and positives, so a window costs only geometry (negative mining tests every window).
class NegativeWindowTest {
 public:
  NegativeWindowTest(const Labels& labels, const SampleConfig& config);
  bool operator()(const Box& window) const;

 private:
  std::vector<Box> ignored_, positives_;
  double maxIgnoreCoverage_ = 0.5, maxNegativeIou_ = 0.3;
};

struct NegativeHarvest {
  std::vector<Sample> samples;
  std::size_t windowsScanned = 0;   // all windows the scan visited
  std::size_t candidates = 0;       // of those: label-free windows the cascade accepts
};

// Which rank of a sharded training job holds an item's pixels: item i lives on rank i % ranks.
struct Shard {
  int rank = 0, ranks = 1;
  bool owns(std::size_t item) const { return static_cast<int>(item % static_cast<std::size_t>(ranks)) == rank; }
};

// Global candidate index held by each of the `wanted` reservoir slots after Algorithm R ran over
// `candidates` candidates with mt19937_64(seed): the same draws harvestNegatives() makes, so a
// sharded harvest (sharded_samples.h) picks the same windows without streaming them in one place.
std::vector<std::size_t> reservoirSlots(std::size_t candidates, std::size_t wanted, std::uint64_t seed);

class TrainingStacks {
 public:
  // Integrates `layers` of every item (hue_distance derived with referenceHue); stacks holding
  // positives get a mirrored copy. Throws when an item lacks a layer.
  // With a shard, only the items this rank owns (and their mirrored copies) are integrated; the
  // others need only labels and reference size (readDatasetItemLabels()).
  // threads (1 = the calling thread, 0 = all cores) share the integrals; the result is the same.
  TrainingStacks(const std::vector<DatasetItem>& items, const std::vector<std::string>& layers,
                 std::optional<double> referenceHue, const SampleConfig& config, Shard shard = {},
                 int threads = 1);

  std::size_t size() const { return integrals_.size(); }
  const IntegralStack& integrals(std::size_t i) const { return integrals_.at(i); }
  const Labels& labels(std::size_t i) const { return labels_.at(i); }
  // Rank holding stack i (mirrored copies live with their original).
  int owner(std::size_t i) const { return owner_.at(i); }
  const Shard& shard() const { return shard_; }
  const std::vector<Sample>& positives() const { return positives_; }
  const SampleConfig& config() const { return config_; }
  std::size_t originalStacks() const { return originals_; }  // [0, originals) are the items

  // Median width / height of the positives (reference pixels); 1 when there are none.
  double positiveAspect() const;

  // Up to `wanted` negatives, sampled uniformly (reservoir, seeded) from the label-free windows of
  // the original stacks that `cascade` accepts (every window when cascade has no stages).
  NegativeHarvest harvestNegatives(const Cascade& cascade, std::size_t wanted, std::uint64_t seed,
                                   int threads) const;

  // The detector the harvest scans with (one accepting every window while `cascade` is empty).
  static Detector harvestDetector(const Cascade& cascade);
  // Label-free windows of original stack s that `detector` accepts, in scan order; adds the
  // windows visited to *scanned.
  std::vector<Box> candidateWindows(const Detector& detector, std::size_t s, int threads,
                                    std::size_t* scanned) const;

 private:
  std::vector<IntegralStack> integrals_;  // empty for stacks of other ranks
  std::vector<int> owner_;
  std::vector<Labels> labels_;  // per stack (mirrored for flipped copies)
  std::vector<Sample> positives_;
  std::size_t originals_ = 0;
  SampleConfig config_;
  Shard shard_;
};


// Horizontally mirrored copy of a stack (every layer and mask) and its labels.
DatasetItem flipItem(const DatasetItem& item);
// The labels of flipItem(item) alone.
Labels flippedLabels(const DatasetItem& item);

}  // namespace fusedet::boosting
