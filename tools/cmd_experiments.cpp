// fusedet experiments: the paper's experiments (Tab. 2-7, Fig. 7) validated across drives with one
// command - per class and configuration (layer / feature subsets, the AND combination), cascades
// trained per fold on the other drives and tested on the held-out drive, pooled over folds: F, AP
// and bootstrap intervals, the paper's claims judged with paired intervals, learning curves,
// OpenCV's HOG people detector as a peer; report.md, results.json and charts in the output
// directory. The rules live in boost/ (data_split, cross_validation, bootstrap, evaluation).

#include <algorithm>
#include <charconv>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "command.h"
#include "data_dir.h"
#include "experiments_peers.h"
#include "experiments_report.h"
#include "fusedet/boost/bootstrap.h"
#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/experiments/experiment_plan.h"
#include "fusedet/boost/learning_curve.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/outcomes_file.h"
#include "fusedet/boost/paired_comparison.h"
#include "fusedet/fusion/kitti_drives.h"
#include "fusedet/fusion/kitti_import.h"
#include "fusedet/fusion/kitti_tracks.h"
#include "fusedet/fusion/layer_sources.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;
using namespace experiments;
using Clock = std::chrono::steady_clock;

struct ExperimentOptions {
  fs::path data = defaultDataDir();
  fs::path out;
  fs::path datasetCache;  // default OUT/dataset
  fs::path modelCache;    // default OUT/fold-models
  fs::path modelsOut;     // optional: the all-layers model per class trained on every frame
  std::string preset = "bundled";  // boosting::experimentPlan(); the fields below override it
  std::vector<std::string> classes = {"car", "person", "bike"};
  std::vector<std::string> configs;        // empty = the preset's
  std::vector<std::string> configClasses;  // empty = the preset's
  std::string van = "ignore";
  double minIou = 0;      // 0 = the devkit's per class (car 0.7, person and bike 0.5)
  int folds = -1;         // -1 = the preset's, 0 = every drive
  int learningFolds = -1;  // -1 = the preset's
  std::vector<std::string> learning;  // training drives per fold for the learning curve
  bool learningSet = false;
  std::vector<std::string> learningPositives;  // training positives per fold for the second curve
  bool learningPositivesSet = false;
  bool trainingScore = true;  // score every learning-curve point on its own training frames
  std::size_t resamples = 0;
  std::uint64_t seed = 1;
  int threads = 0;
  bool peers = true;
  double peerUpscale = 0;  // 0 = the preset's
  // Training; 0 = the preset's.
  int grid = 0, maxStages = 0, maxWeak = 0;
  double targetFalseAlarm = 0;
  std::optional<std::size_t> negatives;  // 0 = the trainer's rule, max(500, 2 x positives)
  double trainScaleFactor = 0, trainStep = 0;
  double scaleFactor = 0;
  double step = 0;
  int minNeighbors = 3;
  bool laserExtent = false;  // boosting::LaserExtentParams on the test frames' detections
  // Per-class detection settings (boost/class_detection.h, car) where the preset uses them; an
  // option given on the command line applies to every class instead.
  bool classDetection = true;
  bool minNeighborsGiven = false, laserExtentGiven = false;
  std::size_t minPositives = 4;
  double stageMaxFalseAlarm = 0.5;                 // a stage is complete at this false-alarm rate
  std::vector<std::string> classStagesText;       // --class-stages as given, parsed by runExperiments
  std::map<std::string, std::size_t> classStages;  // class -> stages its cascades keep (0/absent = all)
  std::vector<std::size_t> stageSweep;             // stage counts the `all` fold cascades are cut to
  std::vector<int> neighborsSweep;                 // min neighbours of that sweep (default: --min-neighbors)
  bool missAnalysis = true;                        // explain every missed positive of `all`
  std::string commandLine;
};

// Layers and feature types of each trained configuration (paper §4).
struct TrainedConfig {
  std::string name;
  std::vector<std::string> layers;
  std::string types;  // feature letters
};
const std::vector<TrainedConfig>& trainedConfigs() {
  static const std::vector<TrainedConfig> c = {
      {"all", fusion::paperPoolLayers(), "a-j"},
      {"no_corners", fusion::paperPoolLayers(), "a-f"},
      {"laser", {"distance", "remission"}, "a-j"},
      {"camera", {"intensity", "hue_distance"}, "a-j"},
      {"four", {"hue_distance", "intensity", "distance", "remission"}, "a-j"},
  };
  return c;
}
const TrainedConfig& trainedConfig(const std::string& name) {
  for (const TrainedConfig& t : trainedConfigs())
    if (t.name == name) return t;
  throw std::runtime_error("unknown configuration '" + name + "' (all, no_corners, laser, camera, four, and)");
}

std::string shortNum(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string joined(const std::vector<std::string>& v, const std::string& sep = ", ") {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

std::string foldsText(std::size_t folds, std::size_t drives) {
  return folds == drives ? "leave-one-drive-out (" + std::to_string(folds) + " folds)"
                         : std::to_string(folds) + " drive-disjoint folds";
}

// " (bundled: 8, quick: 6)": every preset's value of a field (tools/experiments/experiment_plan.h), for --help.
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

std::string learningText(const std::vector<std::size_t>& counts, const std::string& sep = ", ") {
  if (counts.empty()) return "none";
  std::vector<std::string> v;
  for (std::size_t k : counts) v.push_back(k == 0 ? "all" : std::to_string(k));
  return joined(v, sep);
}

// "1,2,all" / "none" -> {1, 2, 0}: the counts of a learning curve (0 = all).
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

// Drive directories under a KITTI root: the three shared ones first (in the documented order),
// then any other directory holding image_2/, label_2/, velodyne/ and calib/.
std::vector<fs::path> kittiDrives(const fs::path& root) {
  const auto isDrive = [](const fs::path& p) {
    return fs::is_directory(p / "image_2") && fs::is_directory(p / "label_2") &&
           fs::is_directory(p / "velodyne") && fs::is_directory(p / "calib");
  };
  if (isDrive(root)) return {root};
  std::vector<fs::path> drives;
  for (const char* known : {"kitti", "kitti_0009", "kitti_object_sample"})
    if (isDrive(root / known)) drives.push_back(root / known);
  std::vector<fs::path> others;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec))
    if (e.is_directory() && isDrive(e.path()) &&
        std::find(drives.begin(), drives.end(), e.path()) == drives.end())
      others.push_back(e.path());
  std::sort(others.begin(), others.end());
  drives.insert(drives.end(), others.begin(), others.end());
  return drives;
}

// The data set to use: --data itself when it is one, else the KITTI drives under it imported
// once into the cache directory (a marker file records a finished import of the same drives).
fs::path resolveDataset(const ExperimentOptions& o) {
  if (fs::exists(o.data / "dataset.json")) {
    std::printf("data set: %s\n", o.data.c_str());
    return o.data;
  }
  const std::vector<fs::path> drives = kittiDrives(o.data);
  if (drives.empty())
    throw std::runtime_error(o.data.string() +
                             ": neither a data set (no dataset.json) nor a directory of KITTI drives "
                             "(image_2/, label_2/, velodyne/, calib/)");
  const fs::path cache = o.datasetCache.empty() ? o.out / "dataset" : o.datasetCache;
  std::string signature;
  for (const auto& d : drives) signature += fs::absolute(d).lexically_normal().string() + "\n";
  const fusion::KittiImportOptions import;
  const fs::path marker = cache / "imported-from.txt";
  if (std::ifstream in(marker); in) {
    std::stringstream s;
    s << in.rdbuf();
    if (s.str() == signature) {
      std::printf("data set: %s (imported earlier from %zu KITTI drives)\n", cache.c_str(), drives.size());
      return cache;
    }
  }
  fs::remove_all(cache);
  for (const fs::path& d : drives) {
    const std::string group = d.filename().string();
    const auto stats = fusion::importKitti(d, group, cache, import);
    std::printf("imported %s -> group %s: %zu frames, %zu labels (%zu ignore regions)\n", d.c_str(),
                group.c_str(), stats.frames, stats.labels, stats.ignoreRegions);
  }
  std::ofstream(marker) << signature;
  return cache;
}


// The raw drive of every manifest entry: from the SOURCE.md of the KITTI directory the entry's
// group was imported from (fusion/kitti_drives.h), else the group itself.
std::vector<std::string> drivesOf(const ExperimentOptions& o, const std::vector<DatasetEntry>& manifest) {
  std::map<std::string, fusion::KittiDriveMap> maps;
  if (!fs::exists(o.data / "dataset.json"))
    for (const fs::path& d : kittiDrives(o.data)) maps[d.filename().string()] = fusion::readKittiDriveMap(d);
  std::vector<std::string> drives;
  for (const DatasetEntry& e : manifest) {
    const auto it = maps.find(e.group);
    const std::string frame = e.id.substr(e.id.find('/') + 1);
    drives.push_back(it == maps.end() ? e.group : it->second.driveOf(frame, e.group));
  }
  return drives;
}

// The physical object of every label (boost/learning_curve.h): "<drive>/track <id>" where the
// KITTI folder has its tracking label file (fusion/kitti_tracks.h), else "" (counted once).
std::vector<std::vector<std::string>> objectIdsOf(const ExperimentOptions& o, const std::vector<DatasetEntry>& manifest,
                                                  const std::vector<Labels>& labels,
                                                  const std::vector<std::string>& driveOf) {
  std::map<std::string, fusion::KittiTracks> tracks;
  if (!fs::exists(o.data / "dataset.json"))
    for (const fs::path& d : kittiDrives(o.data)) tracks[d.filename().string()] = fusion::readKittiTracks(d);
  std::vector<std::vector<std::string>> out(manifest.size());
  for (std::size_t i = 0; i < manifest.size(); ++i) {
    const auto it = tracks.find(manifest[i].group);
    if (it == tracks.end() || it->second.frames.empty()) continue;
    const std::string frame = manifest[i].id.substr(manifest[i].id.find('/') + 1);
    int number = -1;
    const auto [end, ec] = std::from_chars(frame.data(), frame.data() + frame.size(), number);
    if (ec == std::errc() && end == frame.data() + frame.size())
      out[i] = it->second.objectIds(driveOf[i], number, labels[i]);
  }
  return out;
}

// The preset (tools/experiments/experiment_plan.h) with the options given on the command line.
boosting::ExperimentPlan planFor(const ExperimentOptions& o) {
  boosting::ExperimentPlan p = boosting::experimentPlan(o.preset);
  if (o.grid > 0) p.grid = o.grid;
  if (o.maxStages > 0) p.maxStages = o.maxStages;
  if (o.maxWeak > 0) p.maxWeak = o.maxWeak;
  if (o.targetFalseAlarm > 0) p.targetFalseAlarm = o.targetFalseAlarm;
  if (o.negatives) p.negatives = *o.negatives;
  if (o.trainScaleFactor > 0) p.trainScaleFactor = o.trainScaleFactor;
  if (o.trainStep > 0) p.trainStep = o.trainStep;
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

// Grouping of the raw hits, as the options give it (fusedetd's detection.* keys mean the same).
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
  c.stage.maxFalseAlarm = o.stageMaxFalseAlarm;
  c.stage.threads = o.threads;
  c.targetFalseAlarm = p.targetFalseAlarm;
  c.maxStages = p.maxStages;
  c.negativesPerStage = p.negatives;
  c.minPositives = o.minPositives;
  c.seed = o.seed;
  c.threads = o.threads;
  return c;
}

// Stages a class's cascades keep (--class-stages); 0 = every trained stage.
std::size_t keptStages(const ExperimentOptions& o, const std::string& cls) {
  const auto it = o.classStages.find(cls);
  return it == o.classStages.end() ? 0 : it->second;
}

// "person=5,bike=4" -> {person: 5, bike: 4}.
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
  return spec;
}

// Items with their raw drive as group (the folds are drive-disjoint).
std::vector<DatasetItem> loadItems(const fs::path& dataset, const std::vector<DatasetEntry>& entries,
                                   const std::vector<std::string>& driveOf) {
  const std::vector<std::string> layers = {"red", "green", "blue", "intensity", "hue", "distance", "remission"};
  std::vector<DatasetItem> items;
  items.reserve(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    items.push_back(readDatasetItem(dataset, entries[i].id, layers));
    items.back().group = driveOf[i];
  }
  return items;
}

// Measures of pooled frames with their bootstrap intervals.
struct Measured {
  Estimate f, ap;
};
Measured measure(const std::vector<boosting::FrameOutcome>& frames, const boosting::BootstrapConfig& b) {
  std::vector<std::size_t> all(frames.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  Measured m;
  m.f.value = boosting::fMeasureOf(frames, all);
  m.ap.value = boosting::averagePrecisionOf(frames, all);
  m.f.interval = boosting::bootstrapInterval(
      frames.size(), [&](const std::vector<std::size_t>& idx) { return boosting::fMeasureOf(frames, idx); }, b);
  m.ap.interval = boosting::bootstrapInterval(
      frames.size(), [&](const std::vector<std::size_t>& idx) { return boosting::averagePrecisionOf(frames, idx); }, b);
  return m;
}

// Paired difference a - b of F and AP on the same resampled frames (boost/paired_comparison.h).
Claim compare(const std::string& cls, const std::string& key, const std::string& text, const std::string& lhs,
              const std::vector<boosting::FrameOutcome>& a, const std::string& rhs,
              const std::vector<boosting::FrameOutcome>& b, const boosting::BootstrapConfig& boot) {
  const boosting::PairedComparison p = boosting::comparePaired(a, b, boot);
  Claim c;
  c.className = cls;
  c.key = key;
  c.text = text;
  c.lhs = lhs;
  c.rhs = rhs;
  c.fDifference = {p.f.difference, p.f.interval};
  c.apDifference = {p.ap.difference, p.ap.interval};
  c.verdict = p.f.verdict;
  c.apVerdict = p.ap.verdict;
  return c;
}

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

  std::vector<DatasetItem> items = loadItems(dataset, manifest, driveOf);
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
      {"stage min hit / max false alarm", "0.995 / " + shortNum(o.stageMaxFalseAlarm)},
      {"seed (training and bootstrap)", std::to_string(o.seed)},
      {"bootstrap resamples", std::to_string(preset.resamples)},
      {"detection scale factor / step", shortNum(preset.scaleFactor) + " / " + shortNum(preset.step)},
      {"training scan scale factor / step", shortNum(preset.trainScaleFactor) + " / " + shortNum(preset.trainStep)},
      {"grouping", groupingText(o)},
      {"per-class detection (boost/class_detection.h; --no-class-detection: none)", perClassText},
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

  // Training labels per class (boost/class_rules.h trainingLabels()): the evaluation positives,
  // every other label of the class an ignored label; the test frames keep their labels.
  std::map<std::string, std::vector<DatasetItem>> trainItemsOf;  // layers are shared, only labels differ
  for (const std::string& cls : o.classes) {
    const boosting::MatchConfig match = matchFor(cls);
    trainItemsOf[cls] = items;
    for (std::size_t i = 0; i < items.size(); ++i)
      trainItemsOf[cls][i].labels = boosting::trainingLabels(items[i].labels, match);
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
      const auto claim = [&](const std::string& key, const std::string& text, const std::string& a,
                             const std::string& b) {
        if (fr.count(a) && fr.count(b)) report.claims.push_back(compare(cls, key, text, a, fr[a], b, fr[b], boot));
      };
      claim("joint_gt_laser", "joint pool (all layers) > laser only", "all", "laser");
      claim("joint_gt_camera", "joint pool (all layers) > camera only", "all", "camera");
      claim("joint_gt_and", "joint pool (all layers) > laser AND camera", "all", "and");
      claim("four_gt_and", "joint pool (4 layers) > laser AND camera", "four", "and");
      claim("corners_help", "corner features help (all > all without corners)", "all", "no_corners");
      if (cls == "person") claim("joint_gt_hog", "joint pool (all layers) > OpenCV HOG", "all", "hog");
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
    const std::map<std::string, double> targets = {{"car", 0.8}, {"bike", 0.6}, {"person", 0.5}};
    for (const ConfigResult& all : report.results) {
      if (all.config != "all" || !targets.count(all.className)) continue;
      report.goals.push_back({all.className, "F >= " + shortNum(targets.at(all.className)), targets.at(all.className),
                              all.f});
      if (all.className == "person")
        for (const ConfigResult& r : report.results)
          if (r.className == "person" && r.config == "hog" && r.f.value)
            report.goals.push_back(
                {"person", "F >= 2 x HOG's F (" + boosting::formatMeasure(r.f.value) + ")", 2 * *r.f.value, all.f});
    }
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
    if (config == "all" && !r.layerWeightShare.empty())
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
        const boosting::Cascade c = boosting::trainOrLoad(config, trainItems, every, cache, quiet, &tr);
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

const bool registered = registerCommand(
    "experiments",
    "Reproduce the paper's experiments (Tab. 2-7, Fig. 7) with cross-drive validation: F, AP, intervals, claims",
    [](CLI::App& app) {
      auto o = std::make_shared<ExperimentOptions>();
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
                     "fold models, one file per hash of training configuration + training item ids (default: "
                     "OUT/fold-models); reused when present - use a fresh one after changing the trainer");
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
                     "remission), and (laser AND camera; trains both)" +
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
      app.add_option("--grid", o->grid, "feature pool grid, units per side" +
                                            presets(&boosting::ExperimentPlan::grid));
      app.add_option("--max-stages", o->maxStages,
                     "stage limit" + presets(&boosting::ExperimentPlan::maxStages));
      app.add_option("--max-weak", o->maxWeak, "stumps per stage at most" + presets(&boosting::ExperimentPlan::maxWeak));
      app.add_option("--target-fa", o->targetFalseAlarm,
                     "target false-alarm rate of the cascade" +
                         presets(&boosting::ExperimentPlan::targetFalseAlarm));
      app.add_option("--negatives", o->negatives,
                     "negatives per stage; 0 = the trainer's rule, max(500, 2 x positives), as `fusedet train`" +
                         presets(&boosting::ExperimentPlan::negatives));
      app.add_option("--train-scale-factor", o->trainScaleFactor,
                     "scale step of the training scan that bootstraps negatives" +
                         presets(&boosting::ExperimentPlan::trainScaleFactor));
      app.add_option("--train-step", o->trainStep,
                     "position step of that scan, in base-window pixels" +
                         presets(&boosting::ExperimentPlan::trainStep));
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
                   "cluster in the distance layer ends (boost/laser_extent.h; default: off, but car's own setting "
                   "where the preset uses per-class detection); given, it applies to every class");
      app.add_flag("!--no-class-detection", o->classDetection,
                   "detect every class with the general settings (--scale-factor, --step, --min-neighbors, "
                   "--laser-extent or the preset's), also car: by default the bundled preset detects car with its "
                   "own settings (boost/class_detection.h: the daemon's scan 1.1 / 2, more neighbours, laser extent; "
                   "docs/results \"Car at IoU 0.7\"), and any of those four options given applies to every class");
      app.add_option("--max-fa", o->stageMaxFalseAlarm,
                     "false-alarm rate at which a stage is complete, as `fusedet train --max-fa`: lower = fewer, "
                     "longer stages whose sums average more stumps")
          ->check(CLI::Range(1e-6, 0.99))
          ->capture_default_str();
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
          "  fusedet experiments --data ds --out exp --folds 5 --van negative");
      return [o, &app] {
        std::string cmd = "fusedet experiments";
        for (const auto* opt : app.get_options()) {
          if (opt->count() == 0 || opt->get_name() == "--help") continue;
          cmd += " " + opt->get_name();
          if (opt->get_expected_max() == 0) continue;  // a flag
          for (const auto& r : opt->results()) cmd += " " + r;
        }
        o->commandLine = cmd;
        o->minNeighborsGiven = app.count("--min-neighbors") > 0;
        o->laserExtentGiven = app.count("--laser-extent") > 0;
        return runExperiments(*o);
      };
    });

}  // namespace
}  // namespace fusedet::tools
