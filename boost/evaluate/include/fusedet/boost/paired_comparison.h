// SPDX-License-Identifier: Apache-2.0
#pragma once
// Paired comparison of two detectors on the same frames: F and AP of each, and the 95 % bootstrap
// interval of the difference a - b with the frames resampled once for both (bootstrap.h), so a
// frame that is hard for both counts in both. Verdict on "a is better than b": "holds" (interval
// above 0), "contradicted" (below 0), "not shown" (contains 0: a tie).
//
// Used for the paper's claims inside one `fusedet experiments` run and, on two runs' outcomes.json
// files (outcomes_file.h), for an option against the default (`fusedet compare`). Two saved sets
// are only compared when they are the same experiment on the same frames: same class, same
// matching rule (IoU, moderate limits, neighbour classes...) and the same set of frame names;
// anything else is refused with a ComparisonError that says what differs.

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/boost/bootstrap.h"
#include "fusedet/boost/outcomes_file.h"
#include "fusedet/boost/precision_recall.h"

namespace fusedet::boosting {

struct PairedMeasure {
  std::optional<double> a, b, difference;  // on all frames; nullopt where undefined
  std::optional<Interval> interval;        // of a - b over paired resamples
  std::string verdict;                     // verdict(interval)
};

struct PairedComparison {
  std::size_t frames = 0;
  Counts countsA, countsB;
  PairedMeasure f, ap;  // F at the operating point; AP (KITTI, 40 recall points)
};

// a and b: outcomes of the same frames in the same order (std::invalid_argument otherwise).
PairedComparison comparePaired(const std::vector<FrameOutcome>& a, const std::vector<FrameOutcome>& b,
                               const BootstrapConfig& boot = {});

struct ComparisonError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Two saved sets (frames matched by name, in a's order). Refuses different classes, rules or
// frame sets.
PairedComparison compareSets(const OutcomeSet& a, const OutcomeSet& b, const BootstrapConfig& boot = {});

// Which sets to compare; empty = any. configB (needs config): b's configuration paired with a's
// `config` instead of the same name, e.g. a learning-curve point against another of the same run.
// protocolB (needs protocol) likewise: b's fold design paired with a's `protocol`, e.g. the
// learning curve's point on all training frames of 3 folds against the leave-one-drive-out run
// (more training data per fold) - the frames must still be the same (compareSets()).
struct ComparisonFilter {
  std::string className, protocol, config, configB, protocolB;
};
struct ComparisonRow {
  std::string className, protocol, config, configB;  // configB = config unless the filter names another
  std::string protocolB;                             // = protocol unless the filter names another
  PairedComparison result;
};
// Every (class, protocol, configuration) present in both runs and passing the filter (b's
// configuration = filter.configB, its protocol = filter.protocolB when given), in a's order.
// Refuses (ComparisonError) when no set pairs up, listing what each run has, and configB without
// config or protocolB without protocol (std::invalid_argument).
std::vector<ComparisonRow> compareRuns(const RunOutcomes& a, const RunOutcomes& b, const ComparisonFilter& filter,
                                       const BootstrapConfig& boot = {});

}  // namespace fusedet::boosting
