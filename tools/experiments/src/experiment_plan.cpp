// SPDX-License-Identifier: Apache-2.0
#include "fusedet/experiments/experiment_plan.h"

#include <algorithm>
#include <stdexcept>

namespace fusedet::boosting {

ExperimentPlan experimentPlan(const std::string& name) {
  ExperimentPlan p;
  p.name = name;
  if (name == "bundled") {  // the struct's defaults are the bundled models' training
    p.configs = {"all", "no_corners", "laser", "camera", "and"};
    p.configClasses = {"car"};
    p.learningDrives = {1, 2, 4, 8, 0};
    p.learningPositives = {8, 16, 32, 64, 128, 0};
    p.learningFolds = 3;
    return p;
  }
  if (name == "quick") {
    p.grid = 6;
    p.maxStages = 4;
    p.maxWeak = 5;
    p.targetFalseAlarm = 1e-3;
    p.negatives = 200;
    p.trainScaleFactor = 1.5;
    p.trainStep = 6;
    p.scaleFactor = 1.3;
    p.step = 4;
    p.classDetection = false;  // car's own scan (1.1 / 2) would be most of a smoke run's time
    p.folds = 3;
    p.resamples = 200;
    p.configs = {"all", "no_corners", "laser", "camera", "and"};
    p.configClasses = {"car"};
    p.learningDrives = {2, 0};
    p.learningPositives = {16, 0};  // 0 is the drive curve's `all` point: not run twice
    p.learningFolds = 3;
    p.peerUpscale = 1;
    return p;
  }
  std::string known;
  for (const std::string& n : experimentPlanNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown preset '" + name + "' (" + known + ")");
}

const std::vector<std::string>& experimentPlanNames() {
  static const std::vector<std::string> names = {"bundled", "quick"};
  return names;
}

bool runsFor(const ExperimentPlan& plan, const std::string& config, const std::string& cls) {
  if (config == "all" || plan.configClasses.empty()) return true;
  return std::find(plan.configClasses.begin(), plan.configClasses.end(), cls) != plan.configClasses.end();
}

}  // namespace fusedet::boosting
