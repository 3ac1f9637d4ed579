// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/cascade_trainer.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <sstream>
#include <map>
#include <stdexcept>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/negative_miner.h"
#include "fusedet/boost/reference_hue.h"
#include "fusedet/boost/sample_features.h"
#include "fusedet/boost/sharded_samples.h"
#include "fusedet/boost/sharded_stage.h"

namespace fusedet::boosting {

namespace {

using Clock = std::chrono::steady_clock;

// Number formatting for messages: `digits` significant digits, or fixed decimals.
std::string sig(double v, int digits = 3) {
  std::ostringstream o;
  o << std::setprecision(digits) << v;
  return o.str();
}
std::string fixed(double v, int decimals) {
  std::ostringstream o;
  o << std::fixed << std::setprecision(decimals) << v;
  return o.str();
}

}  // namespace

void TrainingConfig::validate() const {
  auto bad = [](const std::string& what) { throw std::invalid_argument("training config: " + what); };
  if (className.empty()) bad("no class name");
  pool.validate();
  if (!(stage.minHit > 0 && stage.minHit <= 1)) bad("min_hit must be in (0, 1]");
  if (!(stage.maxFalseAlarm > 0 && stage.maxFalseAlarm < 1)) bad("max_fa must be in (0, 1)");
  if (stage.maxWeak < 1) bad("rounds per stage must be >= 1");
  if (!(targetFalseAlarm > 0 && targetFalseAlarm < 1)) bad("target false-alarm rate must be in (0, 1)");
  if (maxStages < 1) bad("stage limit must be >= 1");
  if (samples.baseWindowHeight < 4) bad("window height must be >= 4 pixels");
  if (!(samples.scan.scaleFactor > 1)) bad("scan scale factor must be > 1");
  if (!(samples.scan.step > 0)) bad("scan step must be > 0");
}

double classReferenceHue(const std::vector<DatasetItem>& items, const SampleConfig& samples) {
  HueHistogram hist, background;
  for (const DatasetItem& item : items) {
    try {
      for (const Label& l : item.labels)
        if (isPositiveLabel(l, samples)) hist.add(item.stack, l.box);
      background.addImage(item.stack);
    } catch (const std::out_of_range& e) {
      throw std::runtime_error("reference hue: item " + item.id + ": " + e.what());
    }
  }
  return hist.distinctiveHue(background);
}

namespace {
// The network that made the training stacks' neural layers: the same for every item, or the
// cascade would mix features of different networks under one layer name.
NetworkRecord networkOfItems(const std::vector<DatasetItem>& items) {
  if (items.empty()) return {};
  const NetworkRecord& first = items.front().stack.network;
  if (first.empty())
    throw std::runtime_error("item " + items.front().id + " has neural layers from no recorded network (import it "
                             "with fusedet import-kitti --network)");
  for (const DatasetItem& item : items)
    if (!(item.stack.network == first))
      throw std::runtime_error("training items come from different networks: " + items.front().id + " from " +
                               first.text() + ", " + item.id + " from " +
                               (item.stack.network.empty() ? std::string("none") : item.stack.network.text()));
  return first;
}
}  // namespace

Cascade trainCascade(const TrainingConfig& configIn, const std::vector<DatasetItem>& items,
                     ProgressSink& progress, TrainingReport* reportOut, Collective* job) {
  const auto t0 = Clock::now();
  auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  TrainingConfig config = configIn;
  config.samples.className = config.className;
  config.validate();
  TrainingReport report;

  const std::vector<Feature> pool = generatePool(config.pool);
  report.poolSize = pool.size();

  const std::vector<DatasetItem>& train = items;
  const Shard shard = job ? Shard{job->rank(), job->size()} : Shard{};
  std::optional<double> refHue;
  const auto& layers = config.pool.layers;
  if (std::find(layers.begin(), layers.end(), "hue_distance") != layers.end())
    refHue = job ? shardedReferenceHue(train, config.samples, shard, *job) : classReferenceHue(train, config.samples);
  report.referenceHue = refHue;

  const TrainingStacks stacks(train, layers, refHue, config.samples, shard, config.threads);
  report.positives = stacks.positives().size();
  if (stacks.positives().empty())
    throw std::runtime_error("no positives of class '" + config.className + "' in " +
                             std::to_string(train.size()) + " training items (height >= " +
                             sig(config.samples.minPositiveHeight) + " px, occlusion <= " +
                             std::to_string(config.samples.maxOcclusion) + ")");

  Cascade cascade;
  cascade.className = config.className;
  cascade.layers = layers;
  if (usesNetworkLayers(layers)) cascade.network = networkOfItems(train);
  cascade.referenceHue = refHue;
  cascade.windowHeight = config.samples.baseWindowHeight;
  cascade.windowWidth = std::max(
      4, static_cast<int>(std::lround(config.samples.baseWindowHeight * stacks.positiveAspect())));
  // Class-specific minimum detection size: the smallest training positive (as labelled).
  double smallest = std::numeric_limits<double>::max();
  for (const DatasetItem& item : train)
    for (const Label& l : item.labels)
      if (isPositiveLabel(l, config.samples)) smallest = std::min(smallest, l.box.h);
  report.minHeight = std::max(1, static_cast<int>(std::floor(smallest)));
  report.windowWidth = cascade.windowWidth;
  report.windowHeight = cascade.windowHeight;
  const std::size_t wanted = config.negativesPerStage
                                 ? config.negativesPerStage
                                 : std::max<std::size_t>(500, 2 * stacks.positives().size());

  {
    ProgressEvent e;
    e.kind = ProgressKind::kStart;
    e.maxStages = config.maxStages;
    e.positives = stacks.positives().size();
    e.message = "class " + config.className + ": " + std::to_string(pool.size()) +
                " features in the pool (" + std::to_string(layers.size()) + " layers), " +
                std::to_string(stacks.positives().size()) + " positives (" +
                std::to_string(stacks.originalStacks()) + " stacks, mirrored copies included), window " +
                std::to_string(cascade.windowWidth) + "x" + std::to_string(cascade.windowHeight) +
                ", smallest positive " + std::to_string(report.minHeight) + " px high" +
                (refHue ? ", reference hue " + fixed(*refHue, 0) + " deg" : std::string()) + ", " +
                std::to_string(wanted) + " negatives per stage";
    progress.onProgress(e);
  }

  NegativeMiner miner(stacks);
  std::optional<PositiveFeatures> positiveValues;  // built at the first stage
  std::map<std::size_t, int> cascadeIndex;  // pool feature -> Cascade::features index
  std::size_t initialCandidates = 0;
  for (int stage = 1;; ++stage) {
    const auto ts = Clock::now();
    ProgressEvent ev;
    ev.stage = stage;
    ev.maxStages = config.maxStages;
    ev.maxRounds = config.stage.maxWeak;

    // Negatives the cascade still accepts (also measures its false-alarm rate so far).
    const std::size_t want = stage > config.maxStages ? 0 : wanted;
    const std::uint64_t seed = config.seed * 1000003ULL + std::uint64_t(stage);
    const NegativeHarvest harvest = job ? shardedHarvest(stacks, cascade, want, seed, config.threads, *job)
                                        : config.incrementalMining ? miner.harvest(cascade, want, seed, config.threads)
                                                                   : stacks.harvestNegatives(cascade, want, seed, config.threads);
    const double harvestSeconds = std::chrono::duration<double>(Clock::now() - ts).count();
    if (stage == 1) initialCandidates = std::max<std::size_t>(1, harvest.candidates);
    const double cascadeFa = double(harvest.candidates) / double(initialCandidates);
    report.finalFalseAlarm = cascadeFa;
    ev.kind = ProgressKind::kNegatives;
    ev.windowsScanned = harvest.windowsScanned;
    ev.negatives = harvest.samples.size();
    ev.cascadeFalseAlarm = cascadeFa;
    ev.elapsedSeconds = elapsed();
    progress.onProgress(ev);

    if (stage > 1 && cascadeFa <= config.targetFalseAlarm) {
      report.stopReason = "reached the target false-alarm rate: the cascade accepts " +
                          std::to_string(harvest.candidates) + " of " +
                          std::to_string(initialCandidates) + " label-free windows (" +
                          sig(cascadeFa) + " <= " + sig(config.targetFalseAlarm) + ")";
      break;
    }
    if (stage > config.maxStages) {
      report.stopReason = "stage limit " + std::to_string(config.maxStages) +
                          " reached; the cascade accepts " + std::to_string(harvest.candidates) +
                          " of " + std::to_string(initialCandidates) + " label-free windows (" +
                          sig(cascadeFa) + ", target " + sig(config.targetFalseAlarm) + ")";
      break;
    }
    if (harvest.samples.size() < config.minNegatives) {
      report.stopReason = "no negatives left: the cascade accepts only " +
                          std::to_string(harvest.candidates) + " label-free windows of " +
                          std::to_string(harvest.windowsScanned) + " scanned (need " +
                          std::to_string(config.minNegatives) + "); false-alarm rate " +
                          sig(cascadeFa);
      break;
    }

    // Positives the cascade still accepts.
    const std::vector<std::size_t> acceptedIndex = acceptedPositiveIndices(stacks, cascade, job);
    std::vector<Sample> samples;
    for (std::size_t k : acceptedIndex) samples.push_back(stacks.positives()[k]);
    const std::size_t positives = samples.size();
    if (positives < config.minPositives) {
      report.stopReason = "too few positives left: the cascade accepts " + std::to_string(positives) +
                          " of " + std::to_string(stacks.positives().size()) + " (need " +
                          std::to_string(config.minPositives) + ")";
      break;
    }
    samples.insert(samples.end(), harvest.samples.begin(), harvest.samples.end());
    const std::size_t n = samples.size();
    ev.kind = ProgressKind::kStageStart;
    ev.positives = positives;
    ev.negatives = harvest.samples.size();
    progress.onProgress(ev);

    // The pool on every sample, once per stage.
    StageConfig sc = config.stage;
    sc.threads = config.threads;
    const auto onRound = [&](const RoundInfo& info) {
      ev.kind = ProgressKind::kRound;
      ev.round = info.round;
      ev.hitRate = info.hitRate;
      ev.falseAlarm = info.falseAlarm;
      ev.elapsedSeconds = elapsed();
      progress.onProgress(ev);
    };
    const auto tm = Clock::now();
    std::size_t matrixBytes = 0;
    double matrixSeconds = 0;
    auto tb = Clock::now();
    StageResult r;
    if (job) {
      ShardedStage sharded(stacks, pool, samples, positives, *job, config.threads);
      tb = Clock::now();
      matrixSeconds = std::chrono::duration<double>(tb - tm).count();
      matrixBytes = sharded.matrixBytes();
      r = boostStage(
          n, positives,
          [&](std::span<const float> w, std::span<float> chosen) { return sharded.findStump(w, chosen, sc.refineTop); },
          sc, onRound);
    } else {
      // Positives' values from the training-wide cache when it fits, else evaluated each stage
      // (same values either way).
      if (!positiveValues && PositiveFeatures::bytes(pool.size(), stacks.positives().size()) <= config.positiveCacheBytes)
        positiveValues.emplace(stacks, pool, config.threads);
      std::optional<SampleFeatures> all;
      std::optional<StageFeatures> staged;
      if (positiveValues)
        staged.emplace(*positiveValues, acceptedIndex, stacks, pool,
                       std::span<const Sample>(samples).subspan(positives));
      else
        all.emplace(stacks, pool, samples);
      const FeatureMatrix matrix = buildFeatureMatrix(
          pool.size(), n,
          [&](std::size_t first, std::size_t count, std::span<float> out) {
            staged ? staged->block(first, count, out) : all->block(first, count, out);
          },
          config.threads, 1024);
      const FeatureValuesFn raw = [&](std::size_t f, std::span<float> out) {
        staged ? staged->feature(f, out) : all->feature(f, out);
      };
      tb = Clock::now();
      matrixSeconds = std::chrono::duration<double>(tb - tm).count();
      matrixBytes = matrix.bytes();
      r = trainStage(matrix, positives, raw, sc, onRound);
    }

    Stage st;
    st.threshold = r.threshold;
    for (const FittedStump& s : r.stumps) {
      auto it = cascadeIndex.find(s.feature);
      if (it == cascadeIndex.end()) it = cascadeIndex.emplace(s.feature, cascade.addFeature(pool[s.feature])).first;
      st.stumps.push_back(Stump{it->second, double(s.threshold), s.left, s.right});
    }
    cascade.stages.push_back(std::move(st));

    StageReport sr;
    sr.stage = stage;
    sr.weak = static_cast<int>(r.stumps.size());
    sr.hitRate = r.hitRate;
    sr.falseAlarm = r.falseAlarm;
    sr.reachedFalseAlarm = r.reachedFalseAlarm;
    sr.positives = positives;
    sr.negatives = harvest.samples.size();
    sr.windowsScanned = harvest.windowsScanned;
    sr.negativeCandidates = harvest.candidates;
    sr.cascadeFalseAlarm = cascadeFa;
    sr.seconds = std::chrono::duration<double>(Clock::now() - ts).count();
    sr.harvestSeconds = harvestSeconds;
    sr.matrixBytes = matrixBytes;
    sr.matrixSeconds = matrixSeconds;
    sr.boostSeconds = std::chrono::duration<double>(Clock::now() - tb).count();
    report.stages.push_back(sr);

    ev.kind = ProgressKind::kStageDone;
    ev.hitRate = r.hitRate;
    ev.falseAlarm = r.falseAlarm;
    ev.elapsedSeconds = elapsed();
    ev.message = "stage " + std::to_string(stage) + ": " + std::to_string(sr.weak) + " stumps, hit rate " +
                 fixed(r.hitRate, 4) + ", false alarms " + fixed(r.falseAlarm, 4) +
                 (r.reachedFalseAlarm ? "" : " (round limit)") + ", " + std::to_string(positives) +
                 " positives, " + std::to_string(sr.negatives) + " negatives of " +
                 std::to_string(harvest.candidates) + " candidates in " +
                 std::to_string(harvest.windowsScanned) + " windows, " + fixed(sr.seconds, 1) + " s (scan " +
                 fixed(sr.harvestSeconds, 1) + ", features " + fixed(sr.matrixSeconds, 1) + ", boosting " +
                 fixed(sr.boostSeconds, 1) + "), matrix " + fixed(double(sr.matrixBytes) / 1e6, 0) + " MB";
    progress.onProgress(ev);
  }

  report.seconds = elapsed();
  ProgressEvent done;
  done.kind = ProgressKind::kFinished;
  done.stage = static_cast<int>(cascade.stages.size());
  done.maxStages = config.maxStages;
  done.cascadeFalseAlarm = report.finalFalseAlarm;
  done.elapsedSeconds = report.seconds;
  done.message = "stopped after " + std::to_string(report.stages.size()) + " stages (" +
                 std::to_string(cascade.weakCount()) + " stumps): " + report.stopReason;
  progress.onProgress(done);
  if (reportOut) *reportOut = report;
  if (cascade.stages.empty())
    throw std::runtime_error("training produced no stage: " + report.stopReason);
  return cascade;
}

}  // namespace fusedet::boosting
