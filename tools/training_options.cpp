// SPDX-License-Identifier: Apache-2.0
#include "training_options.h"

#include <cstdio>

namespace fusedet::tools {

void TrainingOptions::applyTo(boosting::TrainingConfig& c) const {
  if (grid) c.pool.grid = *grid;
  if (stages) c.maxStages = *stages;
  if (rounds) c.stage.maxWeak = *rounds;
  if (targetFa) c.targetFalseAlarm = *targetFa;
  if (maxFa) c.stage.maxFalseAlarm = *maxFa;
  if (negatives) c.negativesPerStage = *negatives;
  if (scanScaleFactor) c.samples.scan.scaleFactor = *scanScaleFactor;
  if (scanStep) c.samples.scan.step = *scanStep;
}

TrainingDefaults defaultsOf(const boosting::TrainingConfig& c) {
  return [c](TrainingField f) {
    char buf[32];
    switch (f) {
      case TrainingField::kGrid: return " (default: " + std::to_string(c.pool.grid) + ")";
      case TrainingField::kStages: return " (default: " + std::to_string(c.maxStages) + ")";
      case TrainingField::kRounds: return " (default: " + std::to_string(c.stage.maxWeak) + ")";
      case TrainingField::kTargetFa: std::snprintf(buf, sizeof buf, "%g", c.targetFalseAlarm); break;
      case TrainingField::kMaxFa: std::snprintf(buf, sizeof buf, "%g", c.stage.maxFalseAlarm); break;
      case TrainingField::kNegatives: return " (default: " + std::to_string(c.negativesPerStage) + ")";
      case TrainingField::kScanScaleFactor: std::snprintf(buf, sizeof buf, "%g", c.samples.scan.scaleFactor); break;
      case TrainingField::kScanStep: std::snprintf(buf, sizeof buf, "%g", c.samples.scan.step); break;
    }
    return std::string(" (default: ") + buf + ")";
  };
}

void addTrainingOptions(CLI::App& app, TrainingOptions& o, const std::string& scanPrefix,
                        const TrainingDefaults& defaults) {
  using F = TrainingField;
  app.add_option("--grid", o.grid, "feature pool grid: units per side of the unit square the pool is laid on" +
                                       defaults(F::kGrid));
  app.add_option("--stages,--max-stages", o.stages, "stage limit" + defaults(F::kStages));
  app.add_option("--rounds,--max-weak", o.rounds, "boosting rounds (stumps) per stage at most" + defaults(F::kRounds));
  app.add_option("--target-fa", o.targetFa,
                 "stop when the cascade accepts at most this share of the label-free windows" + defaults(F::kTargetFa));
  app.add_option("--max-fa", o.maxFa,
                 "false-alarm rate at which a stage is complete: lower = fewer, longer stages whose sums average "
                 "more stumps" + defaults(F::kMaxFa))
      ->check(CLI::Range(1e-6, 0.99));
  app.add_option("--negatives", o.negatives, "negatives per stage; 0 = max(500, 2 x positives)" + defaults(F::kNegatives));
  app.add_option("--" + scanPrefix + "scale-factor", o.scanScaleFactor,
                 "window scale step of the scan that bootstraps negatives" + defaults(F::kScanScaleFactor));
  app.add_option("--" + scanPrefix + "step", o.scanStep,
                 "position step of that scan, in window pixels at the base size" + defaults(F::kScanStep));
}

}  // namespace fusedet::tools
