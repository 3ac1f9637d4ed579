// SPDX-License-Identifier: Apache-2.0
#pragma once
// Percentile bootstrap intervals over frames: the frames of a test set are resampled with
// replacement (a fixed seed, so a report is reproducible) and a measure is recomputed on each
// resample; the interval is the 2.5 % and 97.5 % quantiles of those values (95 %). Resamples on
// which the measure is undefined (e.g. no positive drawn) are left out and counted.
//
// A comparison of two detectors on the same frames resamples the frames once for both (paired):
// the interval of the difference decides - above 0: the first is better ("holds"), below 0: the
// second is, containing 0: a tie ("not shown").

#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/boost/precision_recall.h"

namespace fusedet::boosting {

struct Interval {
  double lo = 0, hi = 0;
  std::size_t resamples = 0;  // resamples on which the measure was defined
};

struct BootstrapConfig {
  std::size_t resamples = 1000;
  std::uint64_t seed = 1;
  double level = 0.95;
};

// A measure of a set of frames (F, AP, a difference of two...).
using FrameMeasure = std::function<std::optional<double>(const std::vector<std::size_t>& frameIndices)>;

// Interval of `measure` over resamples of the frame indices 0..frames-1; nullopt when the measure
// is undefined on every resample or there are no frames.
std::optional<Interval> bootstrapInterval(std::size_t frames, const FrameMeasure& measure,
                                          const BootstrapConfig& config = {});

// F-measure and AP of the selected frames of one detector.
std::optional<double> fMeasureOf(const std::vector<FrameOutcome>& frames, const std::vector<std::size_t>& indices);
std::optional<double> averagePrecisionOf(const std::vector<FrameOutcome>& frames,
                                         const std::vector<std::size_t>& indices, ApRule rule = ApRule::kKitti40);

// Verdict on "a is better than b" from the interval of (a - b): "holds", "contradicted" or
// "not shown" (a tie: the interval contains 0, or undefined).
std::string verdict(const std::optional<Interval>& difference);

}  // namespace fusedet::boosting
