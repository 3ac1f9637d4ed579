// fusedet experiments: the paper's experiments (Tab. 2-7, Fig. 7) on a data set with one command -
// per class, cascades trained on the layer / feature subsets of the paper, the AND combination of
// laser-only and camera-only, OpenCV's person detectors as peers; report.md, results.json, charts
// and detection mosaics in the output directory.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <opencv2/imgcodecs.hpp>
#include <set>
#include <sstream>

#include "command.h"
#include "data_dir.h"
#include "experiments_data.h"
#include "experiments_peers.h"
#include "experiments_report.h"
#include "experiments_run.h"
#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/fusion/kitti_import.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;
using namespace experiments;
using Clock = std::chrono::steady_clock;

struct ExperimentOptions {
  fs::path data = defaultDataDir();
  fs::path out;
  fs::path datasetCache;  // default OUT/dataset
  fs::path modelsOut;     // optional: the all-layers model per class as <class>.json
  bool quick = false;
  std::vector<std::string> classes = {"car", "person", "bike"};
  std::vector<std::string> configs = {"all", "no_corners", "laser", "camera", "four", "and"};
  std::string van = "negative";
  double trainFraction = 2.0 / 3.0;
  std::uint64_t seed = 1;
  int threads = 0;
  bool peers = true;
  double peerUpscale = 0;  // 0 = 2, or 1 with --quick
  fs::path haarFile = defaultHaarFullbodyPath();
  // Training; -1 / 0 = the preset of --quick or the full run.
  int grid = 0, maxStages = 0, maxWeak = 0;
  double targetFalseAlarm = 0;
  std::size_t negatives = 0;
  // Detection on the test frames.
  double scaleFactor = 0;
  double step = 0;
  int minNeighbors = 3;
  int mosaicTiles = 8;
  std::size_t minPositives = 4;
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
      {"all", {"red", "green", "blue", "intensity", "hue_distance", "distance", "remission"}, "a-j"},
      {"no_corners", {"red", "green", "blue", "intensity", "hue_distance", "distance", "remission"}, "a-f"},
      {"laser", {"distance", "remission"}, "a-j"},
      {"camera", {"intensity", "hue_distance"}, "a-j"},
      {"four", {"hue_distance", "intensity", "distance", "remission"}, "a-j"},
  };
  return c;
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
    const auto stats = fusion::importKitti(d, group, cache, fusion::KittiImportOptions{});
    std::printf("imported %s -> group %s: %zu frames, %zu labels (%zu ignore regions)\n", d.c_str(),
                group.c_str(), stats.frames, stats.labels, stats.ignoreRegions);
  }
  std::ofstream(marker) << signature;
  return cache;
}

class PrintProgress final : public boosting::ProgressSink {
 public:
  explicit PrintProgress(std::string prefix) : prefix_(std::move(prefix)) {}
  void onProgress(const boosting::ProgressEvent& e) override {
    if (e.kind == boosting::ProgressKind::kStart || e.kind == boosting::ProgressKind::kStageDone ||
        e.kind == boosting::ProgressKind::kFinished) {
      std::printf("  [%s %6.1fs] %s\n", prefix_.c_str(), e.elapsedSeconds, e.message.c_str());
      std::fflush(stdout);
    }
  }

 private:
  std::string prefix_;
};

struct Preset {
  int grid, maxStages, maxWeak;
  double targetFalseAlarm;
  std::size_t negatives;
  double trainScaleFactor, trainStep;
  double scaleFactor, step;
};

Preset presetFor(const ExperimentOptions& o) {
  // Full: the pool grid of feature_pool.h (16 units per side), stages of up to 100 stumps.
  // Quick: a coarse pool and a few small stages, to prove the whole pipeline in a few minutes.
  // Full: pool grid 12 (112,084 features over 7 layers; grid 16 has 352,576, ~3x the
  // time per stage), a dense negative scan (32.7 million windows over the 54 training
  // frames) so that the cascade can reach 1e-6 before the negatives run out.
  Preset p = o.quick ? Preset{6, 4, 5, 1e-3, 200, 1.5, 6, 1.3, 4} : Preset{12, 20, 100, 1e-6, 0, 1.1, 2, 1.1, 2};
  if (o.grid > 0) p.grid = o.grid;
  if (o.maxStages > 0) p.maxStages = o.maxStages;
  if (o.maxWeak > 0) p.maxWeak = o.maxWeak;
  if (o.targetFalseAlarm > 0) p.targetFalseAlarm = o.targetFalseAlarm;
  if (o.negatives > 0) p.negatives = o.negatives;
  if (o.scaleFactor > 0) p.scaleFactor = o.scaleFactor;
  if (o.step > 0) p.step = o.step;
  return p;
}

boosting::TrainingConfig trainingConfig(const ExperimentOptions& o, const Preset& p, const std::string& cls,
                                        const TrainedConfig& tc, const boosting::MatchConfig& match) {
  boosting::TrainingConfig c;
  c.className = cls;
  c.pool.grid = p.grid;
  c.pool.layers = tc.layers;
  c.pool.types = boosting::parseFeatureTypes(tc.types);
  c.samples.className = cls;
  c.samples.minPositiveHeight = match.minHeight;
  c.samples.maxOcclusion = match.maxOcclusion;
  c.samples.scan.scaleFactor = p.trainScaleFactor;
  c.samples.scan.step = p.trainStep;
  c.stage.maxWeak = p.maxWeak;
  c.stage.threads = o.threads;
  c.targetFalseAlarm = p.targetFalseAlarm;
  c.maxStages = p.maxStages;
  c.negativesPerStage = p.negatives;
  c.minPositives = o.minPositives;
  c.seed = o.seed;
  c.threads = o.threads;
  return c;
}

std::vector<DatasetItem> loadItems(const fs::path& dataset, const std::vector<DatasetEntry>& entries) {
  static const std::vector<std::string> layers = {"red", "green", "blue", "intensity", "hue", "distance", "remission"};
  std::vector<DatasetItem> items;
  items.reserve(entries.size());
  for (const DatasetEntry& e : entries) items.push_back(readDatasetItem(dataset, e.id, layers));
  return items;
}

ConfigResult resultFrom(const std::string& cls, const std::string& config, const std::string& description,
                        const boosting::CascadeSummary& s, const EvalOutcome& eval) {
  ConfigResult r;
  r.className = cls;
  r.config = config;
  r.description = description;
  r.length = s.length;
  r.stages = s.stages;
  r.layerWeightShare = s.layerWeightShare;
  r.cornerShare = s.cornerShare();
  r.counts = eval.counts;
  r.msPerStack = eval.msPerStack;
  return r;
}

void printResult(const ConfigResult& r) {
  std::printf("%-7s %-11s length %4zu stages %2zu  recall %.2f precision %.2f F %.2f  (%zu hits, %zu false alarms, "
              "%zu misses)  %.1f ms/stack  train %.1f s\n",
              r.className.c_str(), r.config.c_str(), r.length, r.stages, r.counts.recall(), r.counts.precision(),
              r.counts.fMeasure(), r.counts.hits, r.counts.falseAlarms, r.counts.misses, r.msPerStack, r.trainSeconds);
  std::fflush(stdout);
}

cv::Mat mosaicFor(const std::vector<DatasetItem>& test, const EvalOutcome& eval, const std::string& cls,
                  const std::string& config, int maxTiles) {
  // Frames holding positives, evenly spread over them; the frames with the most false alarms
  // fill up when there are fewer. Shown in frame order.
  std::vector<std::size_t> withPositives, others;
  for (std::size_t i = 0; i < test.size(); ++i) (eval.matches[i].positives ? withPositives : others).push_back(i);
  const std::size_t n = static_cast<std::size_t>(std::max(0, maxTiles));
  std::vector<std::size_t> chosen;
  if (withPositives.size() <= n) {
    chosen = withPositives;
  } else {
    for (std::size_t k = 0; k < n; ++k) chosen.push_back(withPositives[k * withPositives.size() / n]);
  }
  std::stable_sort(others.begin(), others.end(), [&](std::size_t a, std::size_t b) {
    return eval.matches[a].falseAlarms > eval.matches[b].falseAlarms;
  });
  for (std::size_t i = 0; i < others.size() && chosen.size() < n; ++i) chosen.push_back(others[i]);
  std::sort(chosen.begin(), chosen.end());
  std::vector<MosaicTile> tiles;
  for (std::size_t i : chosen) {
    MosaicTile t;
    t.bgr = stackToBgr(test[i].stack);
    t.labels = test[i].labels;
    t.detections = eval.detections[i];
    t.match = eval.matches[i];
    t.caption = test[i].id + "  " + cls + " / " + config + ": " + std::to_string(t.match.hits) + " hit, " +
                std::to_string(t.match.falseAlarms) + " false alarm, " + std::to_string(t.match.misses) + " missed";
    tiles.push_back(std::move(t));
  }
  return detectionMosaic(tiles);
}

int runExperiments(ExperimentOptions o) {
  const auto tStart = Clock::now();
  if (o.out.empty()) throw std::runtime_error("--out is required");
  fs::create_directories(o.out);
  const VanPolicy van = parseVanPolicy(o.van);
  const Preset preset = presetFor(o);
  for (const std::string& c : o.configs) {
    const bool known = c == "and" || std::any_of(trainedConfigs().begin(), trainedConfigs().end(),
                                                 [&](const TrainedConfig& t) { return t.name == c; });
    if (!known) throw std::runtime_error("unknown configuration '" + c + "' (all, no_corners, laser, camera, four, and)");
  }

  const fs::path dataset = resolveDataset(o);
  const std::vector<DatasetEntry> manifest = readDatasetManifest(dataset);
  const Split split = splitByFrame(manifest, o.trainFraction);
  std::printf("split: %zu training and %zu test stacks (first %.0f%% of each group's frames train)\n",
              split.train.size(), split.test.size(), 100 * o.trainFraction);

  ExperimentReport report;
  report.command = o.commandLine;
  report.classes = o.classes;
  report.trainStacks = split.train.size();
  report.testStacks = split.test.size();
  {
    std::map<std::string, std::pair<std::size_t, std::size_t>> groups;  // train, test per group
    std::vector<std::string> groupOrder;
    for (const auto& e : split.train) {
      if (!groups.count(e.group)) groupOrder.push_back(e.group);
      groups[e.group].first++;
    }
    for (const auto& e : split.test) {
      if (!groups.count(e.group)) groupOrder.push_back(e.group);
      groups[e.group].second++;
    }
    std::ostringstream d;
    d << "Data set `" << (dataset == o.data ? dataset.string() : o.data.string() + "` imported to `" + dataset.string())
      << "`. Split by frame within each group (drive): the first " << static_cast<int>(std::lround(100 * o.trainFraction))
      << "% of a group's frames (in frame order) train, the rest test. Groups (train / test frames):";
    for (const auto& g : groupOrder) d << " " << g << " " << groups[g].first << " / " << groups[g].second << ";";
    d << " Van is " << (van == VanPolicy::kNegative ? "a hard negative for car (a detection on a van is a false alarm)"
                        : van == VanPolicy::kIgnore ? "an ignore region for car" : "a positive for car")
      << ". Truck, Tram, Misc, Person_sitting and DontCare are ignore regions. Positives: labels of "
         "KITTI \"moderate\" difficulty (box height >= 25 px, occlusion level <= 1); other labels of the "
         "class are neither positives nor false alarms.";
    report.dataDescription = d.str();
  }

  // Instance counts per class and split (person data is scarce in these drives).
  std::vector<Labels> trainLabels, testLabels;
  for (const auto& e : split.train) trainLabels.push_back(readDatasetItemLabels(dataset, e.id).labels);
  for (const auto& e : split.test) testLabels.push_back(readDatasetItemLabels(dataset, e.id).labels);
  std::printf("\n%-7s %16s %16s %12s %16s %16s %12s\n", "class", "train positives", "train ignored", "train frames",
              "test positives", "test ignored", "test frames");
  for (const std::string& cls : o.classes) {
    const boosting::MatchConfig m = matchConfigFor(cls, van);
    const InstanceCount tr = countInstances(trainLabels, m), te = countInstances(testLabels, m);
    report.counts.push_back({cls, tr.positives, tr.ignoredLabels, tr.frames, te.positives, te.ignoredLabels, te.frames});
    std::printf("%-7s %16zu %16zu %12zu %16zu %16zu %12zu\n", cls.c_str(), tr.positives, tr.ignoredLabels, tr.frames,
                te.positives, te.ignoredLabels, te.frames);
  }
  std::printf("\n");
  std::fflush(stdout);

  const std::vector<DatasetItem> trainItems = loadItems(dataset, split.train);
  const std::vector<DatasetItem> testItems = loadItems(dataset, split.test);

  DetectionSetup setup;
  setup.scan.scaleFactor = preset.scaleFactor;
  setup.scan.step = preset.step;
  setup.scan.threads = 1;  // ms per stack on one core, comparable across configurations
  setup.group.minNeighbors = o.minNeighbors;

  report.settings = {
      {"preset", o.quick ? "quick" : "full"},
      {"pool grid (units per side)", std::to_string(preset.grid)},
      {"max stages", std::to_string(preset.maxStages)},
      {"max stumps per stage", std::to_string(preset.maxWeak)},
      {"target false-alarm rate", shortNum(preset.targetFalseAlarm)},
      {"negatives per stage", preset.negatives ? std::to_string(preset.negatives) : "max(500, 2 x positives)"},
      {"stage min hit / max false alarm", "0.995 / 0.5"},
      {"seed", std::to_string(o.seed)},
      {"detection scale factor / step", shortNum(preset.scaleFactor) + " / " + shortNum(preset.step)},
      {"training scan scale factor / step", shortNum(preset.trainScaleFactor) + " / " + shortNum(preset.trainStep)},
      {"grouping", "OpenCV groupRectangles rule, min neighbours " + std::to_string(o.minNeighbors)},
      {"van", toString(van)},
      {"match", "IoU >= 0.5, height >= 25 px, occlusion <= 1"},
  };

  // Peers (person only): camera-only OpenCV detectors on the same test frames.
  if (o.peers && std::find(o.classes.begin(), o.classes.end(), "person") != o.classes.end()) {
    std::vector<std::unique_ptr<PersonPeer>> peers;
    const double upscale = o.peerUpscale > 0 ? o.peerUpscale : (o.quick ? 1.0 : 2.0);
    peers.push_back(makeHogPeer(upscale));
    peers.push_back(makeHaarFullbodyPeer(o.haarFile, upscale));
    const boosting::MatchConfig m = matchConfigFor("person", van);
    for (const auto& peer : peers) {
      ConfigResult r;
      r.className = "person";
      r.config = peer->name();
      r.description = peer->description();
      r.trained = false;
      double ms = 0;
      for (const DatasetItem& item : testItems) {
        const cv::Mat bgr = stackToBgr(item.stack);
        const auto t0 = Clock::now();
        const std::vector<Detection> dets = peer->detect(bgr);
        ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        r.counts.add(boosting::matchDetections(dets, item.labels, m));
      }
      r.msPerStack = testItems.empty() ? 0 : ms / static_cast<double>(testItems.size());
      printResult(r);
      report.results.push_back(r);
    }
  }

  fs::create_directories(o.out / "models");
  if (!o.modelsOut.empty()) fs::create_directories(o.modelsOut);
  const bool wantAnd = std::find(o.configs.begin(), o.configs.end(), "and") != o.configs.end();
  for (const std::string& cls : o.classes) {
    const boosting::MatchConfig match = matchConfigFor(cls, van);
    std::vector<DatasetItem> classTrain = trainItems;
    for (DatasetItem& item : classTrain) item.labels = trainingLabels(item.labels, match);
    std::map<std::string, std::unique_ptr<boosting::Detector>> detectors;
    std::map<std::string, double> trainSeconds;
    std::map<std::string, boosting::CascadeSummary> summaries;
    for (const TrainedConfig& tc : trainedConfigs()) {
      const bool wanted = std::find(o.configs.begin(), o.configs.end(), tc.name) != o.configs.end();
      const bool forAnd = wantAnd && (tc.name == "laser" || tc.name == "camera");
      if (!wanted && !forAnd) continue;
      const boosting::TrainingConfig config = trainingConfig(o, preset, cls, tc, match);
      PrintProgress progress(cls + " " + tc.name);
      boosting::TrainingReport tr;
      const auto t0 = Clock::now();
      boosting::Cascade cascade;
      try {
        cascade = boosting::trainCascade(config, classTrain, progress, &tr);
      } catch (const std::runtime_error& e) {
        // Too little data for this class (person in the shared drives): say so in the report
        // and go on with the other configurations and classes.
        std::printf("%-7s %-11s not trained: %s\n", cls.c_str(), tc.name.c_str(), e.what());
        report.failures.push_back(cls + " / " + tc.name + ": " + e.what());
        continue;
      }
      trainSeconds[tc.name] = std::chrono::duration<double>(Clock::now() - t0).count();
      const boosting::ModelInfo info = {{"experiment", tc.name},
                                        {"layers", joined(tc.layers, " ")},
                                        {"feature_types", tc.types},
                                        {"pool_size", std::to_string(tr.poolSize)},
                                        {"seed", std::to_string(o.seed)},
                                        {"stop_reason", tr.stopReason},
                                        {"command", o.commandLine}};
      boosting::saveModel(cascade, o.out / "models" / (cls + "_" + tc.name + ".json"), info);
      if (tc.name == "all" && !o.modelsOut.empty()) boosting::saveModel(cascade, o.modelsOut / (cls + ".json"), info);
      summaries[tc.name] = boosting::summarizeCascade(cascade);
      detectors[tc.name] = std::make_unique<boosting::Detector>(std::move(cascade));
      if (!wanted) continue;
      const EvalOutcome eval = evaluateChain({detectors[tc.name].get()}, testItems, match, setup);
      ConfigResult r = resultFrom(cls, tc.name, "layers " + joined(tc.layers) + "; features " + tc.types,
                                  summaries[tc.name], eval);
      r.layers = tc.layers;
      r.poolSize = tr.poolSize;
      r.trainSeconds = trainSeconds[tc.name];
      r.stopReason = tr.stopReason;
      printResult(r);
      report.results.push_back(r);
      if (tc.name == "all") {
        cv::imwrite((o.out / ("weight_share_" + cls + ".png")).string(),
                    weightShareChart(cls + ": weight share by layer (all layers)", r.layerWeightShare));
        const cv::Mat mosaic = mosaicFor(testItems, eval, cls, "all", o.mosaicTiles);
        if (!mosaic.empty()) cv::imwrite((o.out / ("detections_" + cls + ".png")).string(), mosaic);
      }
    }
    if (wantAnd && (!detectors.count("laser") || !detectors.count("camera"))) {
      report.failures.push_back(cls + " / and: needs both the laser-only and the camera-only cascade");
    } else if (wantAnd) {
      // Laser first: it scans every window, the camera cascade only sees the survivors.
      const EvalOutcome eval =
          evaluateChain({detectors["laser"].get(), detectors["camera"].get()}, testItems, match, setup);
      ConfigResult r = resultFrom(cls, "and", "laser-only AND camera-only (window accepted by both, then grouped)",
                                  boosting::combineSummaries({summaries["laser"], summaries["camera"]}), eval);
      r.layers = {"distance", "remission", "intensity", "hue_distance"};
      r.trainSeconds = trainSeconds["laser"] + trainSeconds["camera"];
      printResult(r);
      report.results.push_back(r);
    }
  }

  report.totalSeconds = std::chrono::duration<double>(Clock::now() - tStart).count();
  writeReport(o.out, report);
  std::printf("\nwrote %s and %s (%.1f min)\n", (o.out / "report.md").c_str(), (o.out / "results.json").c_str(),
              report.totalSeconds / 60);
  return 0;
}

const bool registered = registerCommand(
    "experiments",
    "Reproduce the paper's experiments (Tab. 2-7, Fig. 7): train and evaluate per class and layer subset",
    [](CLI::App& app) {
      auto o = std::make_shared<ExperimentOptions>();
      app.add_option("--data", o->data,
                     "a data set directory (dataset.json, see docs/dataset-format.md), or a directory of "
                     "KITTI-layout drives (image_2/, label_2/, velodyne/, calib/) that is imported first; "
                     "default: $FUSEDET_DATA or ../shared/data (drives kitti, kitti_0009, kitti_object_sample)")
          ->capture_default_str();
      app.add_option("--out", o->out, "output directory: report.md, results.json, weight_share_<class>.png, "
                                      "detections_<class>.png, models/<class>_<config>.json")
          ->required();
      app.add_option("--dataset-cache", o->datasetCache,
                     "where KITTI drives are imported to (default: OUT/dataset); reused when it holds a finished "
                     "import of the same drives");
      app.add_option("--models-out", o->modelsOut,
                     "also write each class's all-layers model as DIR/<class>.json (scripts/train-models uses "
                     "this for models/)");
      app.add_flag("--quick", o->quick,
                   "small pools (grid 6), at most 4 stages of 5 stumps, coarse scans: the whole pipeline in a few "
                   "minutes, for smoke tests; the numbers mean little");
      app.add_option("--classes", o->classes, "classes to run, in table order")->delimiter(',')->capture_default_str();
      app.add_option("--configs", o->configs,
                     "configurations: all (all layers, features a-j), no_corners (a-f), laser (distance, "
                     "remission), camera (intensity, hue_distance), four (hue_distance, intensity, distance, "
                     "remission), and (laser AND camera; trains both)")
          ->delimiter(',')
          ->capture_default_str();
      app.add_option("--van", o->van, "what a KITTI Van is for car: negative (hard negative), ignore, positive")
          ->check(CLI::IsMember({"negative", "ignore", "positive"}))
          ->capture_default_str();
      app.add_option("--train-fraction", o->trainFraction,
                     "share of each group's frames (the first ones) used for training; the rest test")
          ->check(CLI::Range(0.05, 0.95))
          ->capture_default_str();
      app.add_option("--seed", o->seed, "training seed (same seed + data = same models)")->capture_default_str();
      app.add_option("--threads", o->threads, "training threads, 0 = all cores (detection is timed on one)")
          ->capture_default_str();
      app.add_flag("!--no-peers", o->peers, "skip the OpenCV person peers (HOG, Haar full body)");
      app.add_option("--peer-upscale", o->peerUpscale,
                     "enlarge test images by this factor for the peers, whose windows (64x128, 14x28) exceed "
                     "many KITTI pedestrians (default: 2, quick 1)")
          ->check(CLI::Range(0.5, 4.0));
      app.add_option("--haar-fullbody", o->haarFile, "OpenCV full-body cascade for the peer")->capture_default_str();
      app.add_option("--grid", o->grid, "feature pool grid, units per side (default: 12, quick 6)");
      app.add_option("--max-stages", o->maxStages, "stage limit (default: 20, quick 4)");
      app.add_option("--max-weak", o->maxWeak, "stumps per stage at most (default: 100, quick 5)");
      app.add_option("--target-fa", o->targetFalseAlarm, "target false-alarm rate of the cascade (default: 1e-6, quick 1e-3)");
      app.add_option("--negatives", o->negatives, "negatives per stage (default: max(500, 2 x positives), quick 200)");
      app.add_option("--scale-factor", o->scaleFactor, "detection scale step on the test frames (default: 1.1, quick 1.3)");
      app.add_option("--step", o->step, "detection position step in base-window pixels (default: 2, quick 4)");
      app.add_option("--min-neighbors", o->minNeighbors, "grouping: hits a detection needs")->capture_default_str();
      app.add_option("--mosaic-tiles", o->mosaicTiles, "test frames per detection mosaic")->capture_default_str();
      app.add_option("--min-positives", o->minPositives,
                     "training ends when fewer positives than this are still accepted (person data is scarce)")
          ->capture_default_str();
      app.footer(
          "Per class (car, person, bike) trains cascades on: all layers; all layers without corner features; "
          "laser only (distance, remission); camera only (intensity, hue_distance); 4 layers (hue_distance, "
          "intensity, distance, remission); and evaluates the AND of laser-only and camera-only (a window "
          "must pass both). For person, OpenCV's HOG people detector and haarcascade_fullbody.xml run on the "
          "same test frames. Split: by frame within each group (drive), first two thirds train. Evaluation: "
          "IoU >= 0.5; ignore regions and labels below KITTI moderate (height < 25 px, occlusion > 1) are "
          "neither hits nor false alarms.\n"
          "The detection mosaics contain camera pixels of the data set: do not commit them for KITTI data.\n\n"
          "Examples:\n"
          "  fusedet experiments --out /tmp/exp --quick            # smoke run, a few minutes\n"
          "  fusedet experiments --out /tmp/exp                    # full run (<= 60 min on 2 cores)\n"
          "  fusedet experiments --data ds --out exp --classes car --configs all,laser,camera,and\n"
          "  fusedet experiments --out exp --van ignore --seed 7");
      return [o, &app] {
        std::string cmd = "fusedet experiments";
        for (const auto* opt : app.get_options()) {
          if (opt->count() == 0 || opt->get_name() == "--help") continue;
          cmd += " " + opt->get_name();
          if (opt->get_expected_max() == 0) continue;  // a flag
          for (const auto& r : opt->results()) cmd += " " + r;
        }
        o->commandLine = cmd;
        return runExperiments(*o);
      };
    });

}  // namespace
}  // namespace fusedet::tools
