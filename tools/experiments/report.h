// SPDX-License-Identifier: Apache-2.0
#pragma once
// `fusedet experiments`, output side: report.md (cross-drive tables with 95 % bootstrap intervals,
// the paper's claims judged with paired intervals, learning curves, goals), results.json, and the
// charts: precision-recall curves and learning curve per class, weight share by layer (Fig. 7).
// The numbers come from the library (fusedet/experiments/cross_validation.h, bootstrap.h); this only prints.

#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fusedet/boost/bootstrap.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/learning_curve.h"
#include "fusedet/boost/miss_analysis.h"
#include "fusedet/boost/precision_recall.h"

namespace fusedet::tools::experiments {

// A measure on the pooled frames and its 95 % bootstrap interval over frames.
struct Estimate {
  std::optional<double> value;
  std::optional<boosting::Interval> interval;
};

// One configuration (trained pool subset, AND combination or peer) for one class, pooled over
// the folds.
struct ConfigResult {
  std::string className;
  std::string config;       // "all", "no_corners", "laser", "camera", "four", "and", "hog", ...
  std::string description;  // what it is, for the report
  bool trained = true;      // false for peers (no length, training time, weight shares)
  std::vector<std::string> layers;
  double meanLength = 0, meanStages = 0;  // over the trained folds (AND: both cascades)
  boosting::Counts counts;                // pooled at the operating point
  Estimate f, ap;                         // F at the operating point; AP (KITTI, 40 recall points)
  std::vector<boosting::PrPoint> curve;
  double msPerStack = 0;
  double trainSeconds = 0;                          // summed over folds (~0 for cached folds)
  double cachedTrainSeconds = 0;                    // what the cached folds' model files record
  std::map<std::string, double> layerWeightShare;   // over all folds' cascades, sums to 1
  double cornerShare = 0;                           // share of weak classifiers that are corners
  std::size_t folds = 0, cachedFolds = 0;
  std::vector<std::string> failures;                // folds that could not be trained, and why
};

// "a is better than b", judged on the paired bootstrap interval of the difference.
struct Claim {
  std::string className, key, text, lhs, rhs;
  Estimate fDifference, apDifference;
  std::string verdict;    // on F: "holds", "contradicted", "not shown"
  std::string apVerdict;  // the same on AP
};

// One point of a learning curve: a class's "all" configuration trained on a subset of each fold's
// training frames - `drives` drives (axis "drives") or frames holding at least `requested`
// positives (axis "positives"; 0 = all) - scored on the held-out frames and on its own training
// frames (bias against variance).
struct LearningPoint {
  std::string className;
  std::string axis = "drives";  // "drives" or "positives"
  std::size_t drives = 0;       // axis "drives": training drives per fold (at most)
  std::size_t requested = 0;    // axis "positives": at least this many per fold (0 = all)
  std::vector<boosting::TrainingSetCount> perFold;  // what each fold really trained on
  boosting::Counts counts;
  Estimate f, ap;
  bool trainingScored = false;  // the three below are set
  boosting::Counts trainingCounts;
  Estimate trainingF, trainingAp;  // intervals over (fold, training frame) pairs

  double meanPositives() const;  // training positives per fold, mean over folds
};

// One point of a stage-count sweep: a class's `all` fold cascades cut to their first `stages`
// stages (boosting::firstStages, no retraining) and grouped with `minNeighbors`.
struct SweepPoint {
  std::string className;
  std::size_t stages = 0;
  int minNeighbors = 0;
  double meanStages = 0, meanLength = 0;  // what the cut fold cascades really have
  boosting::Counts counts;
  Estimate f, ap;
};

// Where a configuration's missed positives were lost (boosting::summariseMisses over all folds).
struct MissResult {
  std::string className, config;
  boosting::MissBreakdown breakdown;
  double localisationIou = 0.3;
  int minNeighbors = 3;
  double minIou = 0.5;  // the class's hit overlap the analysis used
};

struct ClassCounts {
  std::string className;
  std::size_t positives = 0, ignoredLabels = 0, frames = 0, drivesWithPositives = 0;
  std::size_t objects = 0;  // distinct physical objects among the positives (fusedet/boost/learning_curve.h)
};

// A goal of the issue ("car F >= 0.8"): the measured F, its interval and whether it is met.
struct Goal {
  std::string className, text;
  double target = 0;
  Estimate measured;
};

struct ExperimentReport {
  std::string title = "fusedet experiments: cross-drive validation";
  std::string command;          // the command line that produced it
  std::string dataDescription;  // data set, drives and folds, one paragraph
  std::vector<std::string> folds;  // held-out drives of each fold
  std::size_t stacks = 0;
  std::vector<std::string> classes;  // table order
  std::vector<ClassCounts> counts;
  std::vector<ConfigResult> results;
  std::vector<Claim> claims;
  std::vector<LearningPoint> learning;
  std::string learningFolds;  // the learning curve's fold design, e.g. "3 drive-disjoint folds"
  std::vector<SweepPoint> sweep;
  std::vector<MissResult> misses;
  std::vector<Goal> goals;
  std::map<std::string, std::string> settings;  // shown in a table and in results.json
  std::vector<std::string> notes;               // facts the run wants the reader to know
  double totalSeconds = 0;
  // Training of every fold cascade the run used: done in this run, and recorded in the model
  // files of the cached ones (their training when they were made; each model once, also when
  // several configurations use it) - together the run's training without a cache.
  double trainSeconds = 0, cachedTrainSeconds = 0;
  double loadAverage = -1;  // 1-minute load average at the end (shared machine), < 0 unknown
};

// Configurations in the order of the paper's tables, with their captions.
struct ConfigInfo {
  std::string config, caption;
};
const std::vector<ConfigInfo>& paperConfigs();

// Layer order for charts and tables: the paper's Fig. 3 order, unknown layers after them.
std::vector<std::string> orderedLayers(const std::map<std::string, double>& shares);
// Source names (fusion::toString(LayerSource)) in the order camera, laser, other.
std::vector<std::string> orderedSources(const std::set<std::string>& sources);
// weight_share_<class>.png for `all` (paper Fig. 7), weight_share_<config>_<class>.png otherwise.
std::string weightShareChartName(const std::string& cls, const std::string& config);

// "0.58 [0.41, 0.72]", "null" when undefined.
std::string formatEstimate(const Estimate& e, int decimals = 2);

std::string renderMarkdown(const ExperimentReport& report);
nlohmann::json toJson(const ExperimentReport& report);

// Bar chart of weight share per layer (paper Fig. 7), one bar per layer, as an 8-bit BGR image.
cv::Mat weightShareChart(const std::string& title, const std::map<std::string, double>& shares);

// A line chart with x and y in [0, xMax] x [0, 1]: one polyline + dots per series, legend.
struct Series {
  std::string name;
  std::vector<std::pair<double, double>> points;  // (x, y)
  std::vector<std::pair<double, double>> band;    // optional (lo, hi) per point: drawn as whiskers
};
cv::Mat lineChart(const std::string& title, const std::string& xLabel, const std::string& yLabel, double xMax,
                  const std::vector<Series>& series);

// learning_<class>.png: held-out and training F and AP against training drives per fold and, beside
// it, against training positives per fold (whichever curves the points hold); empty Mat if none.
cv::Mat learningChart(const std::string& cls, const std::vector<LearningPoint>& points);

// Writes report.md and results.json into `dir` (created if needed).
void writeReport(const std::filesystem::path& dir, const ExperimentReport& report);

}  // namespace fusedet::tools::experiments
