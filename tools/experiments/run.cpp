// SPDX-License-Identifier: Apache-2.0
// fusedet experiments: the paper's experiments (Tab. 2-7, Fig. 7) validated across drives with one
// command - per class and configuration (layer / feature subsets, the AND combination), cascades
// trained per fold on the other drives and tested on the held-out drive, pooled over folds: F, AP
// and bootstrap intervals, the paper's claims judged with paired intervals, learning curves,
// OpenCV's HOG people detector as a peer; report.md, results.json and charts in the output
// directory. The rules live in boost/ (data_split, bootstrap, evaluation) and in
// fusedet/experiments/cross_validation.h.

#include "run.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "claims.h"
#include "data.h"
#include "fusedet/boost/bootstrap.h"
#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/boost/learning_curve.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/outcomes_file.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/experiments/experiment_plan.h"
#include "fusedet/experiments/training_labels.h"
#include "fusedet/fusion/layer_sources.h"
#include "peers.h"
#include "report.h"
#include "text.h"

namespace fusedet::tools::experiments {
namespace {
using Clock = std::chrono::steady_clock;

double loadAverage() {
  std::ifstream f("/proc/loadavg");
  double l = -1;
  if (f) f >> l;
  return l;
}

void printLine(const ConfigResult& r) {
  std::printf("%-7s %-11s F %s  AP %s  (%zu hits, %zu false alarms, %zu misses; length %.0f; %.0f s training, %zu "
              "cached folds, %zu untrained)\n",
              r.className.c_str(), r.config.c_str(), formatEstimate(r.f).c_str(), formatEstimate(r.ap).c_str(),
              r.counts.hits, r.counts.falseAlarms, r.counts.misses, r.meanLength, r.trainSeconds, r.cachedFolds,
              r.failures.size());
  std::fflush(stdout);
}
}  // namespace

int runExperiments(ExperimentOptions o) {
  const auto tStart = Clock::now();
  if (o.out.empty()) throw std::runtime_error("--out is required");
  fs::create_directories(o.out);
  const boosting::VanPolicy van = boosting::parseVanPolicy(o.van);
  const auto matchFor = [&](const std::string& cls) { return boosting::matchConfigFor(cls, van, o.minIou); };
  o.classStages = parseClassStages(o.classStagesText);
  for (const auto& [cls, n] : o.classStages)
    if (std::find(o.classes.begin(), o.classes.end(), cls) == o.classes.end())
      throw std::runtime_error("--class-stages: class '" + cls + "' is not among --classes (" + joined(o.classes) + ")");
  const boosting::ExperimentPlan preset = planFor(o);
  const std::vector<std::string>& configs = preset.configs;
  for (const std::string& c : configs)
    if (c != "and") trainedConfig(c);  // throws for unknown names
  const bool withNetwork = needsNetwork(configs);
  if (withNetwork && !o.network.enabled() && !fs::exists(o.data / "dataset.json"))
    throw std::runtime_error("the configurations all_neural and neural train on a network's score layers: name it "
                             "with --network (darknet or yolov5-onnx)");
  const fs::path cache = o.modelCache.empty() ? o.out / "fold-models" : o.modelCache;
  boosting::BootstrapConfig boot;
  boot.resamples = preset.resamples;
  boot.seed = o.seed;

  const fs::path dataset = resolveDataset(o);
  const std::vector<DatasetEntry> manifest = readDatasetManifest(dataset);
  const std::vector<std::string> driveOf = drivesOf(o, manifest);
  const std::vector<boosting::Fold> folds = boosting::crossGroupFolds(driveOf, static_cast<std::size_t>(preset.folds));
  // The learning curve's folds: the same as the others' unless the preset deals fewer.
  const bool learningOnSameFolds = preset.learningFolds == preset.folds;
  const std::vector<boosting::Fold> learningFolds =
      learningOnSameFolds ? folds : boosting::crossGroupFolds(driveOf, static_cast<std::size_t>(preset.learningFolds));
  const std::size_t driveCount = std::set<std::string>(driveOf.begin(), driveOf.end()).size();

  ExperimentReport report;
  report.command = o.commandLine;
  report.classes = o.classes;
  report.stacks = manifest.size();
  for (const auto& f : folds) report.folds.push_back(joined(f.testGroups, "+"));
  {
    std::map<std::string, std::size_t> framesPerDrive;
    for (const auto& d : driveOf) framesPerDrive[d]++;
    std::ostringstream d;
    d << "Data set `" << (dataset == o.data ? dataset.string() : o.data.string() + "` imported to `" + dataset.string())
      << "`: " << manifest.size() << " frames from " << driveCount
      << " raw drives (grouped by the drive each folder's SOURCE.md names; frames:";
    for (const auto& [drive, n] : framesPerDrive) d << " " << drive << " " << n << ";";
    d << "). " << (folds.size() == driveCount ? "Leave-one-drive-out: " + std::to_string(folds.size()) +
                                                   " folds, each tests one drive on cascades trained on all others."
                                              : std::to_string(folds.size()) +
                                                   " drive-disjoint folds (drives sorted by name, dealt round-robin); "
                                                   "each tests its drives on cascades trained on the others.")
      << " Every frame is tested exactly once; the numbers pool all folds. No fold is skipped: a held-out "
         "drive without positives still counts its false alarms, so skipping it would not be neutral.";
    report.dataDescription = d.str();
  }
  std::printf("%zu frames, %zu drives, %zu folds\n", manifest.size(), driveCount, folds.size());

  std::vector<Labels> labels;
  for (const auto& e : manifest) labels.push_back(readDatasetItemLabels(dataset, e.id).labels);
  const std::vector<std::vector<std::string>> objectIds = objectIdsOf(o, manifest, labels, driveOf);
  boosting::Fold everyItem;  // every item as training items: the data set's counts
  for (std::size_t i = 0; i < labels.size(); ++i) everyItem.train.push_back(i);
  for (const std::string& cls : o.classes) {
    const boosting::MatchConfig m = matchFor(cls);
    const boosting::InstanceCount n = boosting::countInstances(labels, m);
    std::set<std::string> drives;
    for (std::size_t i = 0; i < labels.size(); ++i)
      if (boosting::countInstances({labels[i]}, m).positives) drives.insert(driveOf[i]);
    const std::size_t objects = boosting::countTrainingSet(everyItem, labels, driveOf, objectIds, m).objects;
    report.counts.push_back({cls, n.positives, n.ignoredLabels, n.frames, drives.size(), objects});
    std::printf("%-7s %zu positives (moderate) in %zu frames of %zu drives, %zu ignored labels, %zu distinct objects\n",
                cls.c_str(), n.positives, n.frames, drives.size(), n.ignoredLabels, objects);
  }
  std::fflush(stdout);

  std::vector<DatasetItem> items = loadItems(dataset, manifest, driveOf, withNetwork);
  boosting::DetectionSetup setup;
  setup.scan.scaleFactor = preset.scaleFactor;
  setup.scan.step = preset.step;
  setup.scan.threads = 1;  // ms per stack on one core, comparable across configurations
  setup.group = groupParams(o);
  setup.laserExtent.enabled = o.laserExtent;
  // A class's own detection settings (class_detection.h) where the preset uses them, unless the
  // command line set that option for every class.
  const bool perClass = preset.classDetection && o.classDetection;
  const boosting::SetForEveryClass given{o.scaleFactor > 0, o.step > 0, o.minNeighborsGiven, o.laserExtentGiven};
  const auto setupFor = [&](const std::string& cls) {
    return perClass ? boosting::classDetectionSetup(cls, setup, given) : setup;
  };
  std::string perClassText = "none: every class with the settings above";
  if (perClass)
    for (const std::string& cls : o.classes)
      if (boosting::classDetectionDefault(cls)) {
        const boosting::DetectionSetup s = setupFor(cls);
        perClassText = (perClassText.rfind("none", 0) == 0 ? "" : perClassText + "; ") + cls + ": scale factor " +
                       shortNum(s.scan.scaleFactor) + " / step " + shortNum(s.scan.step) + ", min neighbours " +
                       std::to_string(s.group.minNeighbors) + ", laser extent " + (s.laserExtent.enabled ? "on" : "off");
      }

  report.settings = {
      {"preset", preset.name},
      {"configurations (`all`: every class)",
       joined(configs) + (preset.configClasses.empty() ? std::string()
                                                       : "; other than `all` for " + joined(preset.configClasses) + " only")},
      {"learning curve (training drives per fold)",
       learningText(preset.learningDrives) + " on " + foldsText(learningFolds.size(), driveCount)},
      {"learning curve (training positives per fold)",
       learningText(preset.learningPositives) + " on " + foldsText(learningFolds.size(), driveCount)},
      {"learning curve scored on its training frames", preset.trainingScore ? "yes" : "no"},
      {"folds", foldsText(folds.size(), driveCount)},
      {"pool grid (units per side)", std::to_string(preset.grid)},
      {"max stages", std::to_string(preset.maxStages)},
      {"max stumps per stage", std::to_string(preset.maxWeak)},
      {"target false-alarm rate", shortNum(preset.targetFalseAlarm)},
      {"negatives per stage", preset.negatives ? std::to_string(preset.negatives) : "max(500, 2 x positives)"},
      {"stage min hit / max false alarm", "0.995 / " + shortNum(o.training.maxFa.value_or(boosting::StageConfig{}.maxFalseAlarm))},
      {"seed (training and bootstrap)", std::to_string(o.seed)},
      {"bootstrap resamples", std::to_string(preset.resamples)},
      {"detection scale factor / step", shortNum(preset.scaleFactor) + " / " + shortNum(preset.step)},
      {"training scan scale factor / step", shortNum(preset.trainScaleFactor) + " / " + shortNum(preset.trainStep)},
      {"grouping", groupingText(o)},
      {"per-class detection (fusedet/boost/class_detection.h; --no-class-detection: none)", perClassText},
      {"laser-extent box refinement (--laser-extent)",
       o.laserExtent ? "on: left/right edges widened to the distance layer's object cluster" : "off"},
      {"van for car", boosting::toString(van)},
      {"hit overlap (IoU)", o.minIou > 0 ? shortNum(o.minIou) + " for every class (--min-iou)"
                                         : "the devkit's: car " + shortNum(boosting::kittiMinOverlap("car")) +
                                               ", person and bike " + shortNum(boosting::kittiMinOverlap("person"))},
      {"fold model cache", cache.string()},
  };
  if (!o.classStages.empty()) {
    std::string kept;
    for (const auto& [cls, n] : o.classStages) kept += (kept.empty() ? "" : ", ") + cls + " " + std::to_string(n);
    report.settings["stages kept per class (cut after training; --class-stages)"] = kept;
  }

  boosting::NullProgress quiet;
  const auto log = [](const std::string& line) {
    std::printf("  %s\n", line.c_str());
    std::fflush(stdout);
  };
  std::map<std::string, std::map<std::string, std::vector<boosting::FrameOutcome>>> framesOf;  // class, config

  // Peer (person only): OpenCV's HOG people detector on every frame (it is not trained here).
  if (o.peers && std::find(o.classes.begin(), o.classes.end(), "person") != o.classes.end()) {
    const double upscale = preset.peerUpscale;
    const std::unique_ptr<PersonPeer> peer = makeHogPeer(upscale);
    const boosting::MatchConfig m = matchFor("person");
    ConfigResult r;
    r.className = "person";
    r.config = peer->name();
    r.description = peer->description();
    r.trained = false;
    std::vector<boosting::FrameOutcome> frames;
    double ms = 0;
    for (const DatasetItem& item : items) {
      const cv::Mat bgr = stackToBgr(item.stack);
      const auto t0 = Clock::now();
      const std::vector<Detection> dets = peer->detect(bgr);
      ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      frames.push_back(boosting::frameOutcome(dets, boosting::matchDetections(dets, item.labels, m)));
    }
    r.msPerStack = items.empty() ? 0 : ms / static_cast<double>(items.size());
    r.counts = boosting::countsOf(boosting::allFrames(frames));
    const Measured mm = measure(frames, boot);
    r.f = mm.f;
    r.ap = mm.ap;
    r.curve = boosting::precisionRecallCurve(boosting::allFrames(frames));
    printLine(r);
    report.results.push_back(r);
    framesOf["person"][r.config] = std::move(frames);
  }

  std::size_t mostDrives = 0;  // training drives of the largest learning-curve fold
  for (const auto& f : learningFolds) mostDrives = std::max(mostDrives, boosting::trainingGroupCount(f, driveOf));
  std::vector<std::size_t> learning;  // 0 ("all") = every training drive of the fold
  for (std::size_t k : preset.learningDrives) learning.push_back(k == 0 ? mostDrives : std::min(k, mostDrives));
  report.learningFolds = foldsText(learningFolds.size(), driveCount);

  // Training labels per class (fusedet/boost/class_rules.h trainingLabels()): the evaluation positives,
  // every other label of the class an ignored label; the test frames keep their labels. With
  // --train-labels they come from that data set's copy of each item (training_labels.h).
  std::vector<Labels> trainLabels = labels;
  if (!o.trainLabels.empty()) {
    trainLabels = boosting::readTrainingLabels(o.trainLabels, items);
    o.trainLabelsKey = boosting::labelsKey(trainLabels);
    std::string counts;
    for (const std::string& cls : o.classes) {
      const boosting::MatchConfig m = matchFor(cls);
      counts += (counts.empty() ? "" : "; ") + cls + " " +
                std::to_string(boosting::countInstances(trainLabels, m).positives) + " positives (" +
                std::to_string(boosting::countInstances(labels, m).positives) + " in the data set tested on)";
    }
    report.settings["training labels (--train-labels)"] = "`" + o.trainLabels.string() + "` (labels key " +
                                                          o.trainLabelsKey + "): " + counts;
    std::printf("training labels from %s: %s\n", o.trainLabels.c_str(), counts.c_str());
  }
  std::map<std::string, std::vector<DatasetItem>> trainItemsOf;  // layers are shared, only labels differ
  for (const std::string& cls : o.classes) {
    const boosting::MatchConfig match = matchFor(cls);
    trainItemsOf[cls] = items;
    for (std::size_t i = 0; i < items.size(); ++i)
      trainItemsOf[cls][i].labels = boosting::trainingLabels(trainLabels[i], match);
  }

  // Claims, goals and charts from what is measured so far; the report is rewritten after every
  // step, so a run stopped early still leaves a report of what it finished (marked partial).
  std::map<std::string, boosting::FoldModel> foldModels;  // every fold model the run used, as first used
  // Rows besides the configurations whose test-frame outcomes go to outcomes.json too: stage-sweep
  // points ("all:stages=6,nb=2") and learning-curve points ("all:drives=4", "all:positives=32").
  struct ExtraOutcomes {
    std::string className, config;
    std::size_t folds = 0;
    std::vector<boosting::FrameOutcome> frames;
  };
  std::vector<ExtraOutcomes> extraOutcomes;
  const auto writeSoFar = [&](bool finished) {
    report.cachedTrainSeconds = 0;
    for (const auto& [key, m] : foldModels) report.cachedTrainSeconds += m.cached ? m.trainSeconds : 0;
    report.claims.clear();
    report.goals.clear();
    for (const std::string& cls : o.classes) {
      auto& fr = framesOf[cls];
      judgeClaims(report, cls, fr, boot);
      std::vector<Series> pr;
      for (const ConfigResult& r : report.results) {
        if (r.className != cls || r.curve.empty()) continue;
        Series se{r.config, {}, {}};
        for (const auto& pt : r.curve) se.points.push_back({pt.recall, pt.precision});
        pr.push_back(std::move(se));
      }
      if (!pr.empty())
        cv::imwrite((o.out / ("pr_" + cls + ".png")).string(),
                    lineChart(cls + ": precision-recall, all folds pooled", "recall", "precision", 1.0, pr));
      if (const cv::Mat chart = learningChart(cls, report.learning); !chart.empty())
        cv::imwrite((o.out / ("learning_" + cls + ".png")).string(), chart);
    }
    setGoals(report);
    report.notes.erase(std::remove_if(report.notes.begin(), report.notes.end(),
                                      [](const std::string& n) { return n.rfind("PARTIAL", 0) == 0; }),
                       report.notes.end());
    if (!finished)
      report.notes.insert(report.notes.begin(),
                          "PARTIAL: written while the run was still going; configurations or learning-curve points "
                          "missing here were not finished.");
    report.totalSeconds = std::chrono::duration<double>(Clock::now() - tStart).count();
    report.loadAverage = loadAverage();
    writeReport(o.out, report);
    // Per-frame outcomes of every row, for paired comparisons with other runs (`fusedet compare`).
    boosting::RunOutcomes outcomes;
    outcomes.command = o.commandLine;
    const auto addSet = [&](const std::string& cls, const std::string& config, std::size_t foldCount,
                            const std::vector<boosting::FrameOutcome>& frames) {
      for (const boosting::OutcomeSet& x : outcomes.sets)  // e.g. two learning counts capped to the same
        if (x.className == cls && x.folds == foldCount && x.config == config) return;
      boosting::OutcomeSet set;
      set.className = cls;
      set.protocol = boosting::protocolName(foldCount, driveCount);
      set.folds = foldCount;
      set.config = config;
      set.rule = matchFor(cls);
      for (const DatasetEntry& e : manifest) set.frameIds.push_back(e.id);
      set.frames = frames;
      outcomes.sets.push_back(std::move(set));
    };
    for (const ConfigResult& r : report.results) {
      const auto c = framesOf.find(r.className);
      if (c != framesOf.end() && c->second.count(r.config)) addSet(r.className, r.config, folds.size(), c->second.at(r.config));
    }
    for (const ExtraOutcomes& x : extraOutcomes) addSet(x.className, x.config, x.folds, x.frames);
    boosting::writeOutcomes(o.out / "outcomes.json", outcomes);
  };

  const auto runConfig = [&](const std::string& cls, const std::string& config) {
    const boosting::MatchConfig match = matchFor(cls);
    std::printf("%s / %s:\n", cls.c_str(), config.c_str());
    boosting::ChainSpec spec = chainFor(o, preset, cls, config, match);
    spec.analyseMisses = o.missAnalysis && config == "all";
    const boosting::CrossValidationResult cv =
        boosting::crossValidate(spec, trainItemsOf[cls], items, folds, match, setupFor(cls), cache, quiet, log);
    if (spec.analyseMisses)
      report.misses.push_back({cls, config, boosting::summariseMisses(cv.positives), boosting::MissAnalysisConfig{}.localisationIou,
                               setupFor(cls).group.minNeighbors, match.minIou});
    ConfigResult r;
    r.className = cls;
    r.config = config;
    r.description = config == "and" ? "laser-only AND camera-only (a window must pass both, then grouped)"
                                    : "layers " + joined(trainedConfig(config).layers) + "; features " +
                                          trainedConfig(config).types;
    r.layers = config == "and" ? std::vector<std::string>{"distance", "remission", "intensity", "hue_distance"}
                               : trainedConfig(config).layers;
    r.counts = boosting::countsOf(boosting::allFrames(cv.frames));
    const Measured mm = measure(cv.frames, boot);
    r.f = mm.f;
    r.ap = mm.ap;
    r.curve = boosting::precisionRecallCurve(boosting::allFrames(cv.frames));
    r.msPerStack = cv.msPerStack;
    r.trainSeconds = cv.trainSeconds;
    r.cachedTrainSeconds = cv.cachedTrainSeconds;
    report.trainSeconds += cv.trainSeconds;
    foldModels.insert(cv.models.begin(), cv.models.end());
    r.folds = folds.size();
    r.cachedFolds = cv.cachedFolds;
    r.failures = cv.failures;
    if (!cv.summaries.empty()) {
      const boosting::CascadeSummary sum = boosting::combineSummaries(cv.summaries);
      r.meanLength = static_cast<double>(sum.length) / static_cast<double>(cv.summaries.size());
      r.meanStages = static_cast<double>(sum.stages) / static_cast<double>(cv.summaries.size());
      r.layerWeightShare = sum.layerWeightShare;
      r.cornerShare = sum.cornerShare();
    }
    printLine(r);
    // Keep the table order of --configs whatever order the phases ran in.
    const auto rank = [&](const ConfigResult& x) {
      const auto it = std::find(configs.begin(), configs.end(), x.config);
      return std::make_pair(std::find(o.classes.begin(), o.classes.end(), x.className) - o.classes.begin(),
                            x.trained ? it - configs.begin() : -1);
    };
    report.results.push_back(r);
    std::stable_sort(report.results.begin(), report.results.end(),
                     [&](const ConfigResult& x, const ConfigResult& y) { return rank(x) < rank(y); });
    framesOf[cls][config] = cv.frames;
    if ((config == "all" || config == "all_neural") && !r.layerWeightShare.empty())
      cv::imwrite((o.out / weightShareChartName(cls, config)).string(),
                  weightShareChart(cls + ": weight share by layer (" + config + ", all folds)", r.layerWeightShare));
  };

  // Phase 1, the headline: the joint pool of every class. Phase 2: the paper's other
  // configurations (the claims). Phase 3: learning curves.
  const bool wantAll = std::find(configs.begin(), configs.end(), "all") != configs.end();
  if (wantAll)
    for (const std::string& cls : o.classes) {
      runConfig(cls, "all");
      writeSoFar(false);
    }
  // Stage-count sweep: the `all` fold cascades (now in the cache) cut and regrouped, no training.
  if (wantAll && !o.stageSweep.empty())
    for (const std::string& cls : o.classes) {
      const boosting::MatchConfig match = matchFor(cls);
      boosting::ChainSpec spec = chainFor(o, preset, cls, "all", match);
      const std::vector<int> neighbours = o.neighborsSweep.empty() ? std::vector<int>{o.minNeighbors} : o.neighborsSweep;
      for (std::size_t stages : o.stageSweep)
        for (int mn : neighbours) {
          spec.keepStages = stages;
          boosting::DetectionSetup s = setupFor(cls);
          s.group.minNeighbors = mn;
          s.scan.threads = o.threads;  // nothing is timed here
          const boosting::CrossValidationResult cv =
              boosting::crossValidate(spec, trainItemsOf[cls], items, folds, match, s, cache, quiet);
          SweepPoint p;
          p.className = cls;
          p.stages = stages;
          p.minNeighbors = mn;
          if (!cv.summaries.empty()) {
            const boosting::CascadeSummary sum = boosting::combineSummaries(cv.summaries);
            p.meanStages = static_cast<double>(sum.stages) / static_cast<double>(cv.summaries.size());
            p.meanLength = static_cast<double>(sum.length) / static_cast<double>(cv.summaries.size());
          }
          p.counts = boosting::countsOf(boosting::allFrames(cv.frames));
          const Measured mm = measure(cv.frames, boot);
          p.f = mm.f;
          p.ap = mm.ap;
          std::printf("%-7s sweep: %2zu stages, min neighbours %d  F %s  AP %s  (%zu hits, %zu false alarms, %zu misses)\n",
                      cls.c_str(), stages, mn, formatEstimate(p.f).c_str(), formatEstimate(p.ap).c_str(), p.counts.hits,
                      p.counts.falseAlarms, p.counts.misses);
          std::fflush(stdout);
          report.sweep.push_back(p);
          extraOutcomes.push_back({cls, "all:stages=" + std::to_string(stages) + ",nb=" + std::to_string(mn), folds.size(),
                                   cv.frames});
          writeSoFar(false);
        }
    }
  for (const std::string& config : configs) {
    if (config == "all") continue;
    for (const std::string& cls : o.classes) {
      if (!boosting::runsFor(preset, config, cls)) continue;
      runConfig(cls, config);
      writeSoFar(false);
    }
  }
  // Learning curves of `all`: over training drives and over training positives per fold, each
  // point also scored on its own training frames. A subset already measured (the same training
  // items in every fold, e.g. "all" on both axes) is not run again.
  std::map<std::pair<std::string, std::vector<std::vector<std::size_t>>>, LearningPoint> measuredSubsets;
  std::map<std::pair<std::string, std::vector<std::vector<std::size_t>>>, std::vector<boosting::FrameOutcome>>
      measuredFrames;  // their held-out outcomes
  const auto learningPoint = [&](const std::string& cls, LearningPoint p, const std::vector<boosting::Fold>& sub,
                                 const std::string& what, const std::string& outcomesName) {
    const boosting::MatchConfig match = matchFor(cls);
    p.perFold.clear();
    for (const boosting::Fold& f : sub) p.perFold.push_back(boosting::countTrainingSet(f, labels, driveOf, objectIds, match));
    std::vector<std::vector<std::size_t>> trainSets;
    for (const boosting::Fold& f : sub) trainSets.push_back(f.train);
    const auto key = std::make_pair(cls, trainSets);
    if (const auto it = measuredSubsets.find(key); it != measuredSubsets.end()) {
      const LearningPoint& m = it->second;
      p.counts = m.counts;
      p.f = m.f;
      p.ap = m.ap;
      p.trainingScored = m.trainingScored;
      p.trainingCounts = m.trainingCounts;
      p.trainingF = m.trainingF;
      p.trainingAp = m.trainingAp;
    } else {
      boosting::ChainSpec spec = chainFor(o, preset, cls, "all", match);
      spec.scoreTrainingItems = preset.trainingScore;
      // The point that trains on every training frame of the curve's folds also says where its
      // cascades lose the objects they were trained on (the method's limit, miss_analysis.h).
      bool fullPoint = sub.size() == learningFolds.size();
      for (std::size_t f = 0; fullPoint && f < sub.size(); ++f) fullPoint = sub[f].train == learningFolds[f].train;
      spec.analyseMisses = o.missAnalysis && spec.scoreTrainingItems && fullPoint;
      std::vector<boosting::FrameOutcome> frames;
      bool headline = !preset.trainingScore && learningOnSameFolds;  // the `all` run already has these frames
      for (std::size_t f = 0; headline && f < sub.size(); ++f) headline = sub[f].train == folds[f].train;
      if (headline) {
        frames = framesOf[cls]["all"];
      } else {
        std::printf("%s / all, %s (learning curve, %s):\n", cls.c_str(), what.c_str(), report.learningFolds.c_str());
        const boosting::CrossValidationResult cv =
            boosting::crossValidate(spec, trainItemsOf[cls], items, sub, match, setupFor(cls), cache, quiet, log);
        report.trainSeconds += cv.trainSeconds;
        foldModels.insert(cv.models.begin(), cv.models.end());
        frames = cv.frames;
        if (spec.analyseMisses)
          report.misses.push_back({cls, "all, on its own training frames (" + report.learningFolds + ")",
                                   boosting::summariseMisses(cv.trainingPositives),
                                   boosting::MissAnalysisConfig{}.localisationIou, setupFor(cls).group.minNeighbors,
                                   match.minIou});
        if (spec.scoreTrainingItems) {
          p.trainingScored = true;
          p.trainingCounts = boosting::countsOf(boosting::allFrames(cv.trainingFrames));
          const Measured own = measure(cv.trainingFrames, boot);
          p.trainingF = own.f;
          p.trainingAp = own.ap;
        }
      }
      p.counts = boosting::countsOf(boosting::allFrames(frames));
      const Measured mm = measure(frames, boot);
      p.f = mm.f;
      p.ap = mm.ap;
      measuredSubsets[key] = p;
      measuredFrames[key] = std::move(frames);
    }
    extraOutcomes.push_back({cls, outcomesName, sub.size(), measuredFrames[key]});
    std::string positives;
    for (const auto& c : p.perFold) positives += (positives.empty() ? "" : "/") + std::to_string(c.positives);
    std::printf("%-7s learning curve: %s  F %s  AP %s; training frames F %s  AP %s (positives per fold %s)\n",
                cls.c_str(), what.c_str(), formatEstimate(p.f).c_str(), formatEstimate(p.ap).c_str(),
                p.trainingScored ? formatEstimate(p.trainingF).c_str() : "-",
                p.trainingScored ? formatEstimate(p.trainingAp).c_str() : "-", positives.c_str());
    std::fflush(stdout);
    report.learning.push_back(p);
    writeSoFar(false);
  };
  if (wantAll)
    for (const std::string& cls : o.classes) {
      for (std::size_t k : learning) {
        LearningPoint p;
        p.className = cls;
        p.axis = "drives";
        p.drives = k;
        std::vector<boosting::Fold> sub;
        for (const auto& f : learningFolds) sub.push_back(boosting::learningCurveFold(f, driveOf, k, o.seed));
        char what[48];
        std::snprintf(what, sizeof what, "%2zu drives", k);
        learningPoint(cls, p, sub, what, "all:drives=" + std::to_string(k));
      }
      const std::vector<std::size_t> positivesOfItem =
          boosting::positivesPerItem(labels, matchFor(cls));
      for (std::size_t n : preset.learningPositives) {
        LearningPoint p;
        p.className = cls;
        p.axis = "positives";
        p.requested = n;
        std::vector<boosting::Fold> sub;
        for (const auto& f : learningFolds) sub.push_back(boosting::learningPositivesFold(f, positivesOfItem, n, o.seed));
        learningPoint(cls, p, sub, n ? ">= " + std::to_string(n) + " positives" : "all positives",
                      "all:positives=" + (n ? std::to_string(n) : std::string("all")));
      }
    }

  // Models on every frame (what cross-drive validation measured, trained on all of it).
  if (!o.modelsOut.empty()) {
    fs::create_directories(o.modelsOut);
    for (const std::string& cls : o.classes) {
      const boosting::MatchConfig match = matchFor(cls);
      const std::vector<DatasetItem>& trainItems = trainItemsOf[cls];
      std::vector<std::size_t> every(items.size());
      for (std::size_t i = 0; i < every.size(); ++i) every[i] = i;
      boosting::TrainingConfig config = trainingConfig(o, preset, cls, trainedConfig("all"), match);
      // The cut the folds were measured with = training with that stage limit (firstStages()).
      if (const std::size_t kept = keptStages(o, cls); kept > 0)
        config.maxStages = std::min(config.maxStages, static_cast<int>(kept));
      try {
        boosting::TrainingReport tr;
        const boosting::Cascade c = boosting::trainOrLoad(config, trainItems, every, cache, o.trainLabelsKey, quiet, &tr);
        boosting::saveModel(c, o.modelsOut / (cls + ".json"),
                            {{"experiment", "all"}, {"trained_on", std::to_string(items.size()) + " frames, every drive"},
                             {"seed", std::to_string(o.seed)}, {"command", o.commandLine}});
        std::printf("wrote %s\n", (o.modelsOut / (cls + ".json")).c_str());
      } catch (const std::runtime_error& e) {
        std::printf("%s: no model on all frames: %s\n", cls.c_str(), e.what());
      }
    }
  }

  writeSoFar(true);
  std::printf("\nwrote %s and %s (%.1f min)\n", (o.out / "report.md").c_str(), (o.out / "results.json").c_str(),
              report.totalSeconds / 60);
  return 0;
}

}  // namespace fusedet::tools::experiments
