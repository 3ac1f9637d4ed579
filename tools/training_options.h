// SPDX-License-Identifier: Apache-2.0
#pragma once
// The options that set how a cascade is trained, defined once for `fusedet train` and `fusedet
// experiments`: each option's names, help and check, and the boosting::TrainingConfig field it
// sets. An option not given leaves the command's own value (train: its defaults; experiments: the
// preset's).

#include <CLI/CLI.hpp>
#include <cstddef>
#include <functional>
#include <optional>
#include <string>

#include "fusedet/boost/cascade_trainer.h"

namespace fusedet::tools {

struct TrainingOptions {
  std::optional<int> grid;                  // feature pool grid, units per side
  std::optional<int> stages;                // stage limit
  std::optional<int> rounds;                // boosting rounds (stumps) per stage at most
  std::optional<double> targetFa;           // the cascade's target false-alarm rate
  std::optional<double> maxFa;              // a stage is complete at this false-alarm rate
  std::optional<std::size_t> negatives;     // per stage; 0 = max(500, 2 x positives)
  std::optional<double> scanScaleFactor;    // the scan that bootstraps negatives
  std::optional<double> scanStep;

  // Sets the fields of the options given.
  void applyTo(boosting::TrainingConfig& c) const;
};

enum class TrainingField { kGrid, kStages, kRounds, kTargetFa, kMaxFa, kNegatives, kScanScaleFactor, kScanStep };

// What the help says a field is when its option is not given, e.g. " (default: 16)".
using TrainingDefaults = std::function<std::string(TrainingField)>;

// " (default: V)" with V the field's value in `c`.
TrainingDefaults defaultsOf(const boosting::TrainingConfig& c);

// Adds --grid, --stages (also --max-stages), --rounds (also --max-weak), --target-fa, --max-fa,
// --negatives and the negative scan's --<scanPrefix>scale-factor / --<scanPrefix>step (experiments:
// "train-", as its --scale-factor is the detection's).
void addTrainingOptions(CLI::App& app, TrainingOptions& o, const std::string& scanPrefix,
                        const TrainingDefaults& defaults);

}  // namespace fusedet::tools
