// SPDX-License-Identifier: Apache-2.0
// fusedet train: trains one class's cascade on a data set (fusedet/boost/cascade_trainer.h) and writes the
// model file (fusedet/boost/model_io.h). Progress: a live status line on a terminal, plain log lines
// otherwise. Started by mpirun/srun, the ranks share the work (docs/distributed.md): each loads
// the pixels of its own items only, rank 0 prints and writes the model.

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "command.h"
#include "training_options.h"
#include "mpi_job.h"
#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/core/dataset.h"

namespace fusedet::tools {
namespace {

struct TrainOptions {
  std::filesystem::path data;
  std::filesystem::path out;
  std::string className = "car";
  std::string layers = "red,green,blue,intensity,hue_distance,distance,remission";
  std::string types = "all";
  int positionStep = 1, sizeStep = 1, minCell = 1;
  int windowHeight = 24;
  double minHit = 0.995;
  TrainingOptions training;  // training_options.h: grid, stages, rounds, false alarms, negatives, scan
  double minHeight = 25;
  int maxOcclusion = 1;
  std::uint64_t seed = 1;
  int threads = 0;
  double split = 2.0 / 3.0;
  std::vector<std::string> groups, trainOnly;
  std::filesystem::path testList;
  std::string progress = "auto";
  bool eval = false;
  double evalScaleFactor = 1.1, evalStep = 2;
  int evalMinNeighbors = 3;
  double mpiTimeout = 1800;
};

std::vector<std::string> splitList(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ','))
    if (!item.empty()) out.push_back(item);
  return out;
}

std::string clock(double seconds) {
  const long s = std::lround(std::max(0.0, seconds));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

// Status line on a terminal, log lines otherwise. ETA: stages still needed to reach the target
// false-alarm rate at max_fa per stage (bounded by the stage limit) times the mean stage time.
class ConsoleProgress final : public boosting::ProgressSink {
 public:
  ConsoleProgress(bool tty, double maxFa, double targetFa) : tty_(tty), maxFa_(maxFa), targetFa_(targetFa) {}

  void onProgress(const boosting::ProgressEvent& e) override {
    using boosting::ProgressKind;
    switch (e.kind) {
      case ProgressKind::kStart:
      case ProgressKind::kFinished:
        line(e.message);
        break;
      case ProgressKind::kStageDone:
        stageSeconds_.push_back(e.elapsedSeconds - stageStart_);
        line(e.message);
        break;
      case ProgressKind::kNegatives:
        stageStart_ = e.elapsedSeconds;
        found_ = e.negatives;
        scanned_ = e.windowsScanned;
        cascadeFa_ = e.cascadeFalseAlarm;
        if (e.stage > e.maxStages) {  // the scan after the last stage only measures the cascade
          if (tty_) status(e, "final false-alarm scan");
        } else if (!tty_) {
          std::fprintf(stderr, "stage %d: %zu negatives found in %zu windows (cascade false-alarm rate %.3g)\n",
                       e.stage, e.negatives, e.windowsScanned, e.cascadeFalseAlarm);
        } else {
          status(e, "bootstrapping");
        }
        break;
      case ProgressKind::kStageStart:
        positives_ = e.positives;
        if (tty_) status(e, "evaluating the pool");
        break;
      case ProgressKind::kRound:
        if (tty_) status(e, "");
        else if (e.round % 10 == 0)
          std::fprintf(stderr, "stage %d round %d: hit rate %.4f, false alarms %.4f, %s elapsed\n", e.stage,
                       e.round, e.hitRate, e.falseAlarm, clock(e.elapsedSeconds).c_str());
        break;
    }
  }

 private:
  void line(const std::string& text) {
    if (tty_) std::fprintf(stderr, "\r\033[K");
    std::fprintf(stderr, "%s\n", text.c_str());
  }
  std::string eta(const boosting::ProgressEvent& e) const {
    if (stageSeconds_.empty()) return "?";
    double mean = 0;
    for (double s : stageSeconds_) mean += s;
    mean /= double(stageSeconds_.size());
    const double fa = std::max(cascadeFa_ * maxFa_, 1e-300);
    double more = fa <= targetFa_ ? 0 : std::ceil(std::log(targetFa_ / fa) / std::log(maxFa_));
    more = std::min(more, double(e.maxStages - e.stage));
    const double inStage = std::max(0.0, mean - (e.elapsedSeconds - stageStart_));
    return "~" + clock(inStage + more * mean);
  }
  void status(const boosting::ProgressEvent& e, const char* phase) {
    std::fprintf(stderr,
                 "\r\033[Kstage %d/%d  round %d/%d  hit %.4f  false alarms %.4f  positives %zu  negatives %zu "
                 "(of %zu windows)  %s  elapsed %s  ETA %s",
                 std::min(e.stage, e.maxStages), e.maxStages, e.round, e.maxRounds, e.hitRate, e.falseAlarm, positives_, found_, scanned_,
                 phase, clock(e.elapsedSeconds).c_str(), eta(e).c_str());
    std::fflush(stderr);
  }

  bool tty_;
  double maxFa_, targetFa_;
  std::vector<double> stageSeconds_;
  double stageStart_ = 0, cascadeFa_ = 1;
  std::size_t found_ = 0, scanned_ = 0, positives_ = 0;
};

// Recall / precision / F-measure of the new cascade on the held-back items, with `fusedet eval`'s
// defaults: the KITTI devkit's 2D rules of fusedet/boost/evaluation.h (moderate, IoU >= 0.7 for car
// and 0.5 for person and bike, DontCare, neighbouring classes ignored) through
// fusedet/boost/chain_evaluation.h; OpenCV-style grouping.
void evaluateHeldBack(const TrainOptions& o, const boosting::Cascade& cascade,
                      const std::vector<std::string>& testIds) {
  if (testIds.empty()) {
    std::printf("eval: no held-back items\n");
    return;
  }
  const boosting::Detector detector(cascade);
  boosting::DetectionSetup setup;
  setup.scan.scaleFactor = o.evalScaleFactor;
  setup.scan.step = o.evalStep;
  setup.scan.threads = o.threads;
  setup.group.minNeighbors = o.evalMinNeighbors;
  boosting::MatchConfig match = boosting::matchConfigFor(cascade.className);
  match.minHeight = o.minHeight;
  match.maxOcclusion = o.maxOcclusion;
  std::vector<DatasetItem> items;
  for (const auto& id : testIds) items.push_back(readDatasetItem(o.data, id));
  const boosting::EvalOutcome r = boosting::evaluateChain({&detector}, items, match, setup);
  const boosting::Counts& counts = r.counts;
  const auto& scan = setup.scan;
  const auto& group = setup.group;
  const double ms = r.msPerStack * double(testIds.size());
  std::printf("eval on %zu held-back items (IoU >= %.2f, height >= %.0f px, occlusion <= %d, scale %.2f, step %.1f, "
              "min neighbours %d): recall %s, precision %s, F-measure %s (hits %zu, misses %zu, false alarms "
              "%zu, ignored %zu); %.1f ms per stack\n",
              testIds.size(), match.minIou, match.minHeight, match.maxOcclusion, scan.scaleFactor, scan.step,
              group.minNeighbors, boosting::formatMeasure(counts.recall(), 3).c_str(),
              boosting::formatMeasure(counts.precision(), 3).c_str(), boosting::formatMeasure(counts.fMeasure(), 3).c_str(), counts.hits, counts.misses,
              counts.falseAlarms, counts.ignored, ms / double(testIds.size()));
  const boosting::CascadeSummary sum = boosting::summarizeCascade(cascade);
  std::printf("cascade: length %zu in %zu stages, corner features %.0f %%, weight share per layer:", sum.length,
              sum.stages, 100 * sum.cornerShare());
  for (const auto& [layer, share] : sum.layerWeightShare) std::printf(" %s %.2f", layer.c_str(), share);
  std::printf("\n");
}

// fusedet train's training settings where no option is given: the trainer's, with a coarser negative
// scan (scale step 1.2, step 2).
boosting::TrainingConfig trainDefaults() {
  boosting::TrainingConfig c;
  c.samples.scan.scaleFactor = 1.2;
  c.samples.scan.step = 2;
  return c;
}

int runTrain(const TrainOptions& o, MpiJob* job) {
  const bool talk = !job || job->rank() == 0;  // only rank 0 prints
  boosting::TrainingConfig c = trainDefaults();
  c.className = o.className;
  c.pool.layers = splitList(o.layers);
  c.pool.types = boosting::parseFeatureTypes(o.types);
  c.pool.positionStep = o.positionStep;
  c.pool.sizeStep = o.sizeStep;
  c.pool.minCellSize = o.minCell;
  c.samples.baseWindowHeight = o.windowHeight;
  c.samples.minPositiveHeight = o.minHeight;
  c.samples.maxOcclusion = o.maxOcclusion;
  c.samples.ignoreClasses = boosting::neighbourClasses(o.className);
  c.stage.minHit = o.minHit;
  o.training.applyTo(c);
  c.seed = o.seed;
  c.threads = o.threads;
  c.validate();
  if (!(o.split > 0 && o.split <= 1)) throw std::runtime_error("--split must be in (0, 1]");

  // Train/test split per group, in manifest (frame) order (fusedet/boost/data_split.h).
  const auto all = readDatasetManifest(o.data);
  const std::set<std::string> groups(o.groups.begin(), o.groups.end()),
      trainOnly(o.trainOnly.begin(), o.trainOnly.end());
  std::vector<DatasetEntry> entries;
  std::set<std::string> present;
  for (const auto& e : all) {
    present.insert(e.group);
    if (groups.empty() || groups.count(e.group) || trainOnly.count(e.group)) entries.push_back(e);
  }
  for (const auto& g : o.groups)
    if (!present.count(g)) throw std::runtime_error(o.data.string() + ": no group '" + g + "'");
  for (const auto& g : o.trainOnly)
    if (!present.count(g)) throw std::runtime_error(o.data.string() + ": no group '" + g + "'");
  const boosting::Split split = boosting::splitByFrame(entries, o.split, trainOnly);
  std::vector<std::string> trainIds, testIds;
  for (const auto& e : split.train) trainIds.push_back(e.id);
  for (const auto& e : split.test) testIds.push_back(e.id);
  if (talk) {
    std::map<std::string, std::pair<std::size_t, std::size_t>> perGroup;
    std::vector<std::string> order;
    for (const auto& e : entries)
      if (!perGroup.count(e.group)) order.push_back(e.group), perGroup[e.group];
    for (const auto& e : split.train) perGroup[e.group].first++;
    for (const auto& e : split.test) perGroup[e.group].second++;
    for (const auto& g : order)
      std::fprintf(stderr, "group %s: %zu items, %zu train, %zu held back\n", g.c_str(),
                   perGroup[g].first + perGroup[g].second, perGroup[g].first, perGroup[g].second);
  }
  if (trainIds.empty()) throw std::runtime_error(o.data.string() + ": no training items selected");
  if (!o.testList.empty() && talk) {
    std::ofstream out(o.testList);
    for (const auto& id : testIds) out << id << "\n";
    if (!out) throw std::runtime_error(o.testList.string() + ": cannot write");
  }

  // Layers to load: hue_distance is derived from hue.
  std::vector<std::string> load;
  for (const auto& l : c.pool.layers) {
    const std::string need = l == "hue_distance" ? "hue" : l;
    if (std::find(load.begin(), load.end(), need) == load.end()) load.push_back(need);
  }
  // A rank loads the pixels of its own items only; of the others just the labels.
  const boosting::Shard shard = job ? boosting::Shard{job->rank(), job->size()} : boosting::Shard{};
  std::vector<DatasetItem> items;
  const auto t0 = std::chrono::steady_clock::now();
  for (std::size_t i = 0; i < trainIds.size(); ++i)
    items.push_back(shard.owns(i) ? readDatasetItem(o.data, trainIds[i], load)
                                  : readDatasetItemLabels(o.data, trainIds[i]));
  if (talk)
    std::fprintf(stderr, "loaded %zu training items (layers %s) in %.1f s\n", items.size(), o.layers.c_str(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  if (job && talk)
    std::fprintf(stderr, "distributed over %d ranks: item i on rank i %% %d (rank 0 on %s holds %zu items)\n",
                 job->size(), job->size(), job->hostName().c_str(),
                 (trainIds.size() + static_cast<std::size_t>(job->size()) - 1) / static_cast<std::size_t>(job->size()));

  const bool tty = o.progress == "tty" || (o.progress == "auto" && isatty(STDERR_FILENO));
  ConsoleProgress console(tty, c.stage.maxFalseAlarm, c.targetFalseAlarm);
  boosting::NullProgress quiet;
  boosting::TrainingReport report;
  const boosting::Cascade cascade =
      boosting::trainCascade(c, items, talk ? static_cast<boosting::ProgressSink&>(console) : quiet, &report, job);
  if (!talk) return 0;  // rank 0 writes the one model

  const std::filesystem::path out = o.out.empty() ? std::filesystem::path(o.className + ".json") : o.out;
  boosting::ModelInfo info = {
      {"data", o.data.filename().string()},
      {"train_items", std::to_string(trainIds.size())},
      {"layers", o.layers},
      {"types", o.types},
      {"grid", std::to_string(c.pool.grid)},
      {"pool_size", std::to_string(report.poolSize)},
      {"positives", std::to_string(report.positives)},
      {"seed", std::to_string(o.seed)},
      {"min_hit", std::to_string(o.minHit)},
      {"max_fa", std::to_string(c.stage.maxFalseAlarm)},
      {"stop_reason", report.stopReason},
  };
  boosting::saveModel(cascade, out, info);
  std::printf("wrote %s: class %s, %zu stages, %zu stumps, window %dx%d, training %.1f s\n", out.string().c_str(),
              cascade.className.c_str(), cascade.stages.size(), cascade.weakCount(), cascade.windowWidth,
              cascade.windowHeight, report.seconds);
  std::printf("stop: %s\n", report.stopReason.c_str());
  if (o.eval) evaluateHeldBack(o, cascade, testIds);
  return 0;
}

const bool registered = registerCommand(
    "train",
    "Train a boosted cascade for one class on a data set (Gentle AdaBoost, joint feature pool)",
    [](CLI::App& app) {
      auto o = std::make_shared<TrainOptions>();
      app.add_option("--data", o->data, "data set directory (docs/dataset-format.md), e.g. from import-kitti")
          ->required();
      app.add_option("-o,--out", o->out,
                     "model file to write (JSON, fusedet/boost/model_io.h); default: <class>.json");
      app.add_option("--class", o->className,
                     "class to train: labels of this class are positives, every other label and the "
                     "background are negatives (car: vans are ignored, as by KITTI's devkit), ignore regions are "
                     "skipped")
          ->capture_default_str();
      app.add_option("--layers", o->layers,
                     "comma-separated layers of the joint feature pool; hue_distance is derived from hue "
                     "with the class's reference hue (computed from the positives and stored in the model); "
                     "neural_person, neural_bicycle, neural_car where the data set was imported with --network "
                     "(the model records that network, and detection then needs the same one)")
          ->capture_default_str();
      app.add_option("--types", o->types,
                     "feature types of the pool: letters a-j (paper Fig. 1) and ranges, e.g. a-f (no corner "
                     "features), g-j, or all")
          ->capture_default_str();
      addTrainingOptions(app, o->training, "", defaultsOf(trainDefaults()));
      app.add_option("--position-step", o->positionStep, "feature positions every n grid units")
          ->capture_default_str();
      app.add_option("--size-step", o->sizeStep, "feature cell sizes every n grid units")->capture_default_str();
      app.add_option("--min-cell", o->minCell, "smallest feature cell in grid units")->capture_default_str();
      app.add_option("--window-height", o->windowHeight,
                     "model window height in pixels (smallest object scanned); the width follows the "
                     "median aspect ratio of the positives")
          ->capture_default_str();
      app.add_option("--min-hit", o->minHit, "hit rate every stage keeps on its positives")->capture_default_str();
      app.add_option("--min-height", o->minHeight, "[px] smaller labels of the class are not used as positives")
          ->capture_default_str();
      app.add_option("--max-occlusion", o->maxOcclusion, "more occluded labels (KITTI level) are not positives")
          ->capture_default_str();
      app.add_option("--seed", o->seed, "seed of the negative sampling (same seed + data = same model file)")
          ->capture_default_str();
      app.add_option("--threads", o->threads, "worker threads (0 = all cores)")->capture_default_str();
      app.add_option("--split", o->split,
                     "share of each group's items (in frame order) used for training; the rest is held back")
          ->capture_default_str();
      app.add_option("--groups", o->groups, "only these groups (default: all); repeatable")->delimiter(',');
      app.add_option("--train-only", o->trainOnly,
                     "groups used entirely for training (no held-back part); repeatable")
          ->delimiter(',');
      app.add_option("--test-list", o->testList, "write the held-back item ids to this file, one per line");
      app.add_flag("--eval", o->eval,
                   "after training, report recall, precision and F-measure on the held-back items (the "
                   "rules and defaults of `fusedet eval`: the KITTI devkit's IoU >= 0.7 for car, 0.5 for person and "
                   "bike, KITTI moderate, ignore regions)");
      app.add_option("--eval-scale-factor", o->evalScaleFactor, "detection scale step for --eval")
          ->capture_default_str();
      app.add_option("--eval-step", o->evalStep, "detection position step for --eval")->capture_default_str();
      app.add_option("--eval-min-neighbors", o->evalMinNeighbors, "grouping: raw hits a detection needs (--eval)")
          ->capture_default_str();
      app.add_option("--mpi-timeout", o->mpiTimeout,
                     "[s] under mpirun/srun: end the job when a rank waits this long for the others in one "
                     "exchange (a rank died or hangs); 0 = wait forever")
          ->capture_default_str();
      app.add_option("--progress", o->progress, "auto (status line on a terminal), tty or log")
          ->capture_default_str()
          ->check(CLI::IsMember({"auto", "tty", "log"}));
      app.footer(
          "Per stage: positives the cascade still accepts; negatives bootstrapped from label-free windows\n"
          "(IoU < 0.3 with every label of the class, not inside ignore regions) that the cascade still\n"
          "accepts; the pool evaluated once and binned; Gentle AdaBoost rounds until the stage's false\n"
          "alarms <= --max-fa at hit rate >= --min-hit. Training ends at --target-fa, at --stages, or when\n"
          "no negatives are left; the last line says which, with the numbers.\n\n"
          "Examples:\n"
          "  fusedet import-kitti --out ds\n"
          "  fusedet train --data ds --class car --out car.json\n"
          "  fusedet train --data ds --class car --layers intensity,hue_distance --types a-f --grid 12\n"
          "  fusedet train --data ds --groups kitti --train-only kitti_0009 --test-list test.txt --eval\n"
          "  mpirun -np 4 --hostfile hosts fusedet train --data ds --class car --out car.json\n\n"
          "Distributed (docs/distributed.md): started by mpirun or srun, the ranks split the training\n"
          "items (item i on rank i mod N, each rank reads only its own pixels), build histograms of their\n"
          "own samples and combine them exactly, so the model file is the same for any number of ranks;\n"
          "rank 0 prints and writes it. A failing rank ends the whole job with its error. Without a\n"
          "launcher fusedet trains in-process and loads no MPI library.");
      return [o] {
        if (!launchedByMpiLauncher()) return runTrain(*o, nullptr);
        const std::unique_ptr<MpiJob> job = openMpiJob(o->mpiTimeout);
        try {
          return runTrain(*o, job.get());
        } catch (const std::exception& e) {
          // The other ranks may be waiting in a collective: end them all, naming this rank.
          std::fprintf(stderr, "fusedet train: error: rank %d of %d (%s): %s\n", job->rank(), job->size(),
                       job->hostName().c_str(), e.what());
          job->abort(1);
        }
        return 1;  // not reached: abort() ends the process
      };
    });

}  // namespace
}  // namespace fusedet::tools
