// SPDX-License-Identifier: Apache-2.0
#include "options.h"

#include <functional>
#include <stdexcept>

#include "fusedet/boost/data_split.h"
#include "fusedet/fusion/layer_sources.h"
#include "text.h"

namespace fusedet::tools::experiments {
namespace {
// " (bundled: 8, quick: 6)": every preset's value of a field (fusedet/experiments/experiment_plan.h),
// for --help.
std::string presets(const std::function<std::string(const boosting::ExperimentPlan&)>& field) {
  std::string s;
  for (const std::string& n : boosting::experimentPlanNames())
    s += (s.empty() ? " (" : ", ") + n + ": " + field(boosting::experimentPlan(n));
  return s + ")";
}

template <typename T>
std::string presets(T boosting::ExperimentPlan::*field) {
  return presets([field](const boosting::ExperimentPlan& p) { return shortNum(static_cast<double>(p.*field)); });
}
}  // namespace

// The paper's seven layers and the network's score layers: the joint pool with one more sensor.
std::vector<std::string> poolWithNetwork() {
  std::vector<std::string> l = fusion::paperPoolLayers();
  for (const std::string& n : fusion::networkPoolLayers()) l.push_back(n);
  return l;
}

const std::vector<TrainedConfig>& trainedConfigs() {
  static const std::vector<TrainedConfig> c = {
      {"all", fusion::paperPoolLayers(), "a-j"},
      {"no_corners", fusion::paperPoolLayers(), "a-f"},
      {"laser", {"distance", "remission"}, "a-j"},
      {"camera", {"intensity", "hue_distance"}, "a-j"},
      {"four", {"hue_distance", "intensity", "distance", "remission"}, "a-j"},
      {"all_neural", poolWithNetwork(), "a-j"},
      {"neural", fusion::networkPoolLayers(), "a-j"},
  };
  return c;
}

const TrainedConfig& trainedConfig(const std::string& name) {
  for (const TrainedConfig& t : trainedConfigs())
    if (t.name == name) return t;
  throw std::runtime_error("unknown configuration '" + name +
                           "' (all, no_corners, laser, camera, four, and, all_neural, neural)");
}

bool needsNetwork(const std::vector<std::string>& configs) {
  for (const std::string& c : configs)
    if (c != "and" && usesNetworkLayers(trainedConfig(c).layers)) return true;
  return false;
}

std::vector<std::size_t> parseLearningCounts(const std::vector<std::string>& values, const std::string& option) {
  std::vector<std::size_t> out;
  for (const std::string& v : values) {
    if (v == "none") continue;
    if (v == "all") {
      out.push_back(0);
      continue;
    }
    std::size_t used = 0;
    unsigned long n = 0;
    try {
      n = std::stoul(v, &used);
    } catch (const std::logic_error&) {
      used = 0;
    }
    if (used != v.size() || n == 0) throw std::runtime_error(option + ": '" + v + "' is not a count >= 1, all or none");
    out.push_back(n);
  }
  return out;
}

boosting::ExperimentPlan planFor(const ExperimentOptions& o) {
  boosting::ExperimentPlan p = boosting::experimentPlan(o.preset);
  const TrainingOptions& t = o.training;
  if (t.grid) p.grid = *t.grid;
  if (t.stages) p.maxStages = *t.stages;
  if (t.rounds) p.maxWeak = *t.rounds;
  if (t.targetFa) p.targetFalseAlarm = *t.targetFa;
  if (t.negatives) p.negatives = *t.negatives;
  if (t.scanScaleFactor) p.trainScaleFactor = *t.scanScaleFactor;
  if (t.scanStep) p.trainStep = *t.scanStep;
  if (o.scaleFactor > 0) p.scaleFactor = o.scaleFactor;
  if (o.step > 0) p.step = o.step;
  if (o.folds >= 0) p.folds = o.folds;
  if (o.learningFolds >= 0) p.learningFolds = o.learningFolds;
  if (o.resamples > 0) p.resamples = o.resamples;
  if (o.peerUpscale > 0) p.peerUpscale = o.peerUpscale;
  if (!o.configs.empty()) p.configs = o.configs;
  if (!o.configClasses.empty()) p.configClasses = o.configClasses;
  if (o.learningSet) p.learningDrives = parseLearningCounts(o.learning, "--learning");
  if (o.learningPositivesSet) p.learningPositives = parseLearningCounts(o.learningPositives, "--learning-positives");
  if (!o.trainingScore) p.trainingScore = false;
  return p;
}

boosting::GroupParams groupParams(const ExperimentOptions& o) {
  boosting::GroupParams g;
  g.minNeighbors = o.minNeighbors;
  return g;
}

std::string groupingText(const ExperimentOptions& o) {
  std::string t = "OpenCV groupRectangles rule, min neighbours " + std::to_string(o.minNeighbors);
  return t;
}

boosting::TrainingConfig trainingConfig(const ExperimentOptions& o, const boosting::ExperimentPlan& p, const std::string& cls,
                                        const TrainedConfig& tc, const boosting::MatchConfig& match) {
  boosting::TrainingConfig c;
  c.className = cls;
  c.pool.grid = p.grid;
  c.pool.layers = tc.layers;
  c.pool.types = boosting::parseFeatureTypes(tc.types);
  c.samples.className = cls;
  c.samples.minPositiveHeight = match.minHeight;  // the evaluation positives (KITTI moderate)
  c.samples.maxOcclusion = match.maxOcclusion;
  c.samples.scan.scaleFactor = p.trainScaleFactor;
  c.samples.scan.step = p.trainStep;
  c.stage.maxWeak = p.maxWeak;
  if (o.training.maxFa) c.stage.maxFalseAlarm = *o.training.maxFa;
  c.stage.threads = o.threads;
  c.targetFalseAlarm = p.targetFalseAlarm;
  c.maxStages = p.maxStages;
  c.negativesPerStage = p.negatives;
  c.minPositives = o.minPositives;
  c.seed = o.seed;
  c.threads = o.threads;
  return c;
}

std::size_t keptStages(const ExperimentOptions& o, const std::string& cls) {
  const auto it = o.classStages.find(cls);
  return it == o.classStages.end() ? 0 : it->second;
}

std::map<std::string, std::size_t> parseClassStages(const std::vector<std::string>& items) {
  std::map<std::string, std::size_t> out;
  for (const std::string& item : items) {
    const auto eq = item.find('=');
    std::size_t n = 0;
    try {
      if (eq == std::string::npos || eq == 0) throw std::invalid_argument(item);
      std::size_t used = 0;
      n = std::stoul(item.substr(eq + 1), &used);
      if (used != item.size() - eq - 1 || n == 0) throw std::invalid_argument(item);
    } catch (const std::logic_error&) {
      throw std::runtime_error("--class-stages: expected CLASS=N with N >= 1 (e.g. person=5), got '" + item + "'");
    }
    out[item.substr(0, eq)] = n;
  }
  return out;
}

boosting::ChainSpec chainFor(const ExperimentOptions& o, const boosting::ExperimentPlan& p, const std::string& cls,
                             const std::string& config, const boosting::MatchConfig& match) {
  boosting::ChainSpec spec;
  if (config == "and") {
    // Laser first: it scans every window, the camera cascade only sees the survivors.
    spec.parts = {trainingConfig(o, p, cls, trainedConfig("laser"), match),
                  trainingConfig(o, p, cls, trainedConfig("camera"), match)};
  } else {
    spec.parts = {trainingConfig(o, p, cls, trainedConfig(config), match)};
  }
  spec.keepStages = keptStages(o, cls);
  spec.trainingLabels = o.trainLabelsKey;
  return spec;
}

void addExperimentOptions(CLI::App& app, const std::shared_ptr<ExperimentOptions>& o) {
  app.add_option("--data", o->data,
                 "a data set directory (dataset.json, see docs/dataset-format.md; its groups are the drives), "
                 "or a directory of KITTI-layout folders (image_2/, label_2/, velodyne/, calib/) that is "
                 "imported first, frames grouped by the raw drive their SOURCE.md names; default: "
                 "$FUSEDET_DATA or ../shared/data")
      ->capture_default_str();
  app.add_option("--out", o->out,
                 "output directory: report.md, results.json, pr_<class>.png, learning_<class>.png, "
                 "weight_share_<class>.png, fold-models/")
      ->required();
  app.add_option("--dataset-cache", o->datasetCache,
                 "where KITTI drives are imported to (default: OUT/dataset); reused when it holds a finished "
                 "import of the same drives");
  app.add_option("--model-cache", o->modelCache,
                 "fold models, one file per hash of training configuration + training item ids (+ the labels of "
                 "--train-labels) (default: "
                 "OUT/fold-models); reused when present - use a fresh one after changing the trainer");
  app.add_option("--train-labels", o->trainLabels,
                 "train on the labels of this data set instead (the same items, e.g. a copy labelled by fusedet "
                 "autolabel: teacher only with --replace-human, or teacher + human); every frame is still scored "
                 "against the labels of --data. Fold models trained on them get their own cache keys")
      ->check(CLI::ExistingDirectory);
  app.add_option("--models-out", o->modelsOut,
                 "also train each class's all-layers cascade on every frame and write DIR/<class>.json");
  app.add_option("--preset", o->preset,
                 "what to run, each part overridable by the options below: bundled = the training of the "
                 "bundled models (models/README.md) and the plan of docs/results: leave-one-drive-out for "
                 "`all` of every class (the headline) and for the paper's configurations (car), learning "
                 "curves of `all` on 3 drive-disjoint folds; quick = the same plan scaled down to a smoke "
                 "test (grid 6, at most 4 stages of 5 stumps, coarse scans, 3 folds; its numbers mean little)")
      ->check(CLI::IsMember(boosting::experimentPlanNames()))
      ->capture_default_str();
  app.add_flag_callback("--quick", [o] { o->preset = "quick"; }, "the same as --preset quick");
  app.add_option("--classes", o->classes, "classes to run, in table order")->delimiter(',')->capture_default_str();
  app.add_option("--configs", o->configs,
                 "configurations: all (all layers, features a-j), no_corners (a-f), laser (distance, "
                 "remission), camera (intensity, hue_distance), four (hue_distance, intensity, distance, "
                 "remission), and (laser AND camera; trains both), all_neural (all + the network's score layers "
                 "neural_person, neural_bicycle, neural_car; needs --network), neural (the score layers alone)" +
                     presets([](const boosting::ExperimentPlan& p) { return joined(p.configs, ","); }))
      ->delimiter(',');
  app.add_option("--config-classes", o->configClasses,
                 "classes the configurations other than `all` run for (`all` runs for every class)" +
                     presets([](const boosting::ExperimentPlan& p) {
                       return p.configClasses.empty() ? std::string("every class") : joined(p.configClasses, ",");
                     }))
      ->delimiter(',');
  app.add_option("--van", o->van,
                 "what a KITTI Van is for car: ignore (the devkit's neighbouring class), negative (false "
                 "alarm), positive")
      ->check(CLI::IsMember({"ignore", "negative", "positive"}))
      ->capture_default_str();
  app.add_option("--min-iou", o->minIou,
                 "a detection hits a label at IoU >= this, for every class; 0 = the KITTI devkit's minimum "
                 "overlap per class: car 0.7, person and bike 0.5 (0.5 for car = PASCAL, as figures before "
                 "2026-11-30 in docs/results)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  app.add_option("--folds", o->folds,
                 "folds of `all` and the configurations: 0 = leave-one-drive-out (every drive is a fold); k = "
                 "drives sorted by name and dealt round-robin into k folds" +
                     presets(&boosting::ExperimentPlan::folds));
  app.add_option("--learning-folds", o->learningFolds,
                 "folds of the learning curve, same meaning; when equal to --folds its `all` point is the "
                 "headline's" +
                     presets(&boosting::ExperimentPlan::learningFolds));
  app.add_option_function<std::vector<std::string>>(
         "--learning",
         [o](const std::vector<std::string>& v) {
           o->learning = v;
           o->learningSet = true;
         },
         "training drives per fold for the learning curve of `all` (a seeded nested subset of each "
         "fold's training drives), all = every one; none = no curve" +
             presets([](const boosting::ExperimentPlan& p) { return learningText(p.learningDrives, ","); }))
      ->delimiter(',');
  app.add_option_function<std::vector<std::string>>(
         "--learning-positives",
         [o](const std::vector<std::string>& v) {
           o->learningPositives = v;
           o->learningPositivesSet = true;
         },
         "the learning curve of `all` over training positives of the class per fold, on the same folds: "
         "a seeded nested random subset of each fold's training frames, taken until it holds at least N "
         "moderate positives (the report records the exact positives, distinct objects - a KITTI tracking "
         "id counts once -, drives and frames per fold); all = every training frame; none = no curve" +
             presets([](const boosting::ExperimentPlan& p) { return learningText(p.learningPositives, ","); }))
      ->delimiter(',');
  app.add_flag_callback(
      "--no-training-score", [o] { o->trainingScore = false; },
      "do not score the learning-curve points on their own training frames (by default every point is: "
      "each fold's cascade detects on the frames it was trained on, same detection and KITTI rules, so "
      "the report shows training F and AP beside held-out F and AP - high training and low held-out F "
      "that close as data grows mean data limits, low training F means method limits)");
  app.add_option("--bootstrap", o->resamples,
                 "bootstrap resamples of the frames" +
                     presets(&boosting::ExperimentPlan::resamples));
  app.add_option("--seed", o->seed, "training and bootstrap seed (same seed + data = same numbers)")
      ->capture_default_str();
  app.add_option("--threads", o->threads, "training threads, 0 = all cores (detection is timed on one)")
      ->capture_default_str();
  app.add_flag("!--no-peers", o->peers, "skip OpenCV's HOG people detector");
  app.add_option("--peer-upscale", o->peerUpscale,
                 "enlarge images by this factor for HOG, whose 64x128 window exceeds many KITTI pedestrians" +
                     presets(&boosting::ExperimentPlan::peerUpscale))
      ->check(CLI::Range(0.5, 4.0));
  addTrainingOptions(app, o->training, "train-", [](TrainingField f) {
    using P = boosting::ExperimentPlan;
    switch (f) {
      case TrainingField::kGrid: return presets(&P::grid);
      case TrainingField::kStages: return presets(&P::maxStages);
      case TrainingField::kRounds: return presets(&P::maxWeak);
      case TrainingField::kTargetFa: return presets(&P::targetFalseAlarm);
      case TrainingField::kNegatives: return presets(&P::negatives);
      case TrainingField::kScanScaleFactor: return presets(&P::trainScaleFactor);
      case TrainingField::kScanStep: return presets(&P::trainStep);
      case TrainingField::kMaxFa: break;
    }
    return defaultsOf(boosting::TrainingConfig{})(f);
  });
  app.add_option("--scale-factor", o->scaleFactor,
                 "detection scale step on the test frames" +
                     presets(&boosting::ExperimentPlan::scaleFactor));
  app.add_option("--step", o->step,
                 "detection position step in base-window pixels" +
                     presets(&boosting::ExperimentPlan::step));
  app.add_option("--min-neighbors", o->minNeighbors,
                 "grouping: hits a detection needs (car: its own where the preset uses per-class detection; "
                 "given, for every class)")
      ->capture_default_str();
  app.add_flag("--laser-extent", o->laserExtent,
               "after grouping, widen each test-frame detection's left and right edges to where its object's "
               "cluster in the distance layer ends (fusedet/boost/laser_extent.h; default: off, but car's own "
               "setting where the preset uses per-class detection); given, it applies to every class");
  app.add_flag("!--no-class-detection", o->classDetection,
               "detect every class with the general settings (--scale-factor, --step, --min-neighbors, "
               "--laser-extent or the preset's), also car: by default the bundled preset detects car with its "
               "own settings (fusedet/boost/class_detection.h: the daemon's scan 1.1 / 2, more neighbours, "
               "laser extent; docs/results \"Car at IoU 0.7\"), and any of those four options given applies to "
               "every class");
  addNetworkOptions(app, o->network,
                    "Needed by the configurations all_neural and neural: the KITTI drives are imported with the "
                    "network's layers (a cache per network).");
  app.add_option("--class-stages", o->classStagesText,
         "per-class stage count, e.g. person=5,bike=4: that class's cascades keep only their first N trained "
         "stages in every configuration and the learning curve (the same cascades as training with a stage "
         "limit of N, which --models-out then does); other classes keep every stage")
      ->delimiter(',');
  app.add_option("--stage-sweep", o->stageSweep,
                 "after each class's `all` configuration, evaluate its fold cascades cut to each of these "
                 "stage counts, e.g. 1,2,3,4,6,8,14 (no retraining; report section \"Stage count and grouping "
                 "sweep\")")
      ->delimiter(',')
      ->check(CLI::PositiveNumber);
  app.add_option("--neighbors-sweep", o->neighborsSweep,
                 "min neighbours the stage sweep groups with, e.g. 1,2,3 (default: --min-neighbors)")
      ->delimiter(',')
      ->check(CLI::Range(0, 1000));
  app.add_flag("!--no-miss-analysis", o->missAnalysis,
               "skip the miss analysis: by default every positive the `all` configuration misses is classified "
               "by the step that lost it - scan geometry (no scanned window reaches the class's hit overlap), "
               "cascade (every such window rejected; at which stage), grouping (accepted, then dropped or "
               "merged), localisation (a detection overlaps it with IoU >= 0.3) - with counts by height, aspect, "
               "occlusion and truncation (report section \"Where the missed positives are lost\"; one more "
               "detection pass over the test frames); the learning curves' point on all training frames, when "
               "scored on its training frames, gets the same analysis of the positives its cascades miss there");
  app.add_option("--min-positives", o->minPositives,
                 "training ends when fewer positives than this are still accepted (person data is scarce)")
      ->capture_default_str();
  app.footer(
      "Frames are grouped by raw KITTI drive (each folder's SOURCE.md); every fold tests its drive(s) "
      "on cascades trained on all other drives, so no physical object is on both sides. Per class "
      "(car, person, bike) and configuration the folds' outcomes are pooled: F at the operating point "
      "and AP (KITTI, 40 recall points) with 95 % bootstrap intervals over frames; the paper's claims "
      "(joint > laser-only, > camera-only, > AND; corners help) are "
      "judged with the paired 95 % interval of the difference: \"holds\" only when it lies above 0, "
      "\"contradicted\" when it lies below 0, \"not shown\" when it contains 0 (a tie); a learning curve "
      "trains `all` on 1, 2, 4, ... drives per fold and on frames holding 8, 16, 32, ... positives per fold, each point also scored on its own training frames. OpenCV's HOG people detector runs on every frame as the person peer. Evaluation: the KITTI "
      "object devkit's 2D rules, moderate (see `fusedet eval --help`). A fold that cannot be trained "
      "(too few positives) counts as detecting nothing.\n"
      "Fold models are cached by a hash of the training settings and training item ids: a rerun with "
      "the same settings reuses them (delete the cache after changing the trainer's code).\n\n"
      "Examples:\n"
      "  fusedet experiments --out /tmp/exp --quick                 # smoke run, a few minutes\n"
      "  nice -n 10 fusedet experiments --out /tmp/exp --threads 2  # docs/results in one run (hours)\n"
      "  fusedet experiments --out exp --classes car --configs all --learning none\n"
      "  fusedet experiments --data ds --out exp --folds 5 --van negative\n"
      "  fusedet experiments --out exp --configs all,all_neural,neural --config-classes car,person,bike \\\n"
      "      --network darknet --networks-dir ../shared/models --learning none --learning-positives none");
}

}  // namespace fusedet::tools::experiments
