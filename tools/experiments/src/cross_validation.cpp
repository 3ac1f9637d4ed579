// SPDX-License-Identifier: Apache-2.0
#include "fusedet/experiments/cross_validation.h"

#include <chrono>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "fusedet/boost/model_io.h"

namespace fusedet::boosting {
namespace {

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : ",") + x;
  return s;
}

// FNV-1a 64 over strings, each followed by a separator byte (so "ab","c" differs from "a","bc").
struct Fnv {
  std::uint64_t h = 0xcbf29ce484222325ull;
  void add(const std::string& s) {
    for (unsigned char ch : s) h = (h ^ ch) * 0x100000001b3ull;
    h = (h ^ 0xffu) * 0x100000001b3ull;
  }
  std::string hex() const {
    char buf[17];
    std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
    return buf;
  }
};

}  // namespace

std::string describeTrainingConfig(const TrainingConfig& c) {
  std::ostringstream d;
  d.precision(17);
  d << "class " << c.className << "\npool grid " << c.pool.grid << " position_step " << c.pool.positionStep
    << " min_cell " << c.pool.minCellSize << " size_step " << c.pool.sizeStep << " layers " << joined(c.pool.layers)
    << " types";
  for (FeatureType t : c.pool.types) d << " " << static_cast<int>(t);
  // "flip 1": positives are always mirrored; the text stays so that cached keys stay.
  d << "\nsamples min_height " << c.samples.minPositiveHeight << " max_occlusion " << c.samples.maxOcclusion
    << " flip 1 max_negative_iou " << c.samples.maxNegativeIou
    << " max_ignore_coverage " << c.samples.maxIgnoreCoverage << " window_height " << c.samples.baseWindowHeight
    << " scan " << c.samples.scan.scaleFactor << " " << c.samples.scan.step << " " << c.samples.scan.minWidth << " "
    << c.samples.scan.minHeight << " " << c.samples.scan.maxWidth << " " << c.samples.scan.maxHeight
    << "\nstage min_hit " << c.stage.minHit << " max_fa " << c.stage.maxFalseAlarm << " max_weak " << c.stage.maxWeak
    << " refine " << c.stage.refineTop << "\ncascade target_fa " << c.targetFalseAlarm << " max_stages "
    << c.maxStages << " negatives " << c.negativesPerStage << " min_negatives " << c.minNegatives
    << " min_positives " << c.minPositives << " seed " << c.seed << "\n";
  // Only when set: keys of configurations without them stay as they were.
  if (!c.samples.ignoreClasses.empty()) d << "ignore_classes " << joined(c.samples.ignoreClasses) << "\n";
  return d.str();
}

std::string trainingKey(const TrainingConfig& config, const std::vector<std::string>& itemIds,
                        const std::string& trainingLabels) {
  Fnv h;
  h.add(describeTrainingConfig(config));
  for (const std::string& id : itemIds) h.add(id);
  // Only when set: keys of models trained on the data set's own labels stay as they were.
  if (!trainingLabels.empty()) h.add("training labels " + trainingLabels);
  return h.hex();
}

std::string labelsKey(const std::vector<Labels>& labels) {
  Fnv h;
  std::ostringstream d;
  d.precision(17);
  for (const Labels& item : labels) {
    d.str("");
    d << "item " << item.size() << "\n";
    for (const Label& l : item)
      d << l.className << "\t" << l.sourceClass << "\t" << l.box.x << " " << l.box.y << " " << l.box.w << " "
        << l.box.h << "\t" << l.truncation << " " << l.occlusion << " " << l.ignore << "\t" << l.origin << "\n";
    h.add(d.str());
  }
  return h.hex();
}

Cascade trainOrLoad(const TrainingConfig& config, const std::vector<DatasetItem>& items,
                    const std::vector<std::size_t>& train, const std::filesystem::path& cacheDir,
                    const std::string& trainingLabels, ProgressSink& progress, TrainingReport* report,
                    bool* fromCache, FoldModel* source) {
  std::vector<DatasetItem> subset;
  std::vector<std::string> ids;
  subset.reserve(train.size());
  for (std::size_t i : train) {
    subset.push_back(items.at(i));  // layers are shared cv::Mat headers, not copied pixels
    ids.push_back(items.at(i).id);
  }
  const std::string key = trainingKey(config, ids, trainingLabels);
  const std::filesystem::path file = cacheDir.empty() ? std::filesystem::path() : cacheDir / (key + ".json");
  if (!file.empty() && std::filesystem::exists(file)) {
    if (fromCache) *fromCache = true;
    Cascade cached = loadModel(file);
    if (source) {
      *source = FoldModel{key, true, 0};
      for (const auto& [k, v] : loadModelInfo(file))
        if (k == "train_seconds") source->trainSeconds = std::strtod(v.c_str(), nullptr);
    }
    return cached;
  }
  if (fromCache) *fromCache = false;
  TrainingReport local;
  Cascade cascade = trainCascade(config, subset, progress, report ? report : &local);
  if (source) *source = FoldModel{key, false, (report ? *report : local).seconds};
  if (!file.empty()) {
    std::filesystem::create_directories(cacheDir);
    const TrainingReport& r = report ? *report : local;
    const std::filesystem::path tmp = file.string() + ".tmp";
    saveModel(cascade, tmp, {{"training_key", key}, {"train_items", std::to_string(ids.size())},
                             {"stop_reason", r.stopReason}, {"train_seconds", std::to_string(r.seconds)},
                             {"positives", std::to_string(r.positives)}});
    std::filesystem::rename(tmp, file);  // a killed run leaves no half-written model
  }
  return cascade;
}

CrossValidationResult crossValidate(const ChainSpec& spec, const std::vector<DatasetItem>& trainingItems,
                                    const std::vector<DatasetItem>& testItems, const std::vector<Fold>& folds,
                                    const MatchConfig& match, const DetectionSetup& setup,
                                    const std::filesystem::path& cacheDir, ProgressSink& progress,
                                    const std::function<void(const std::string&)>& log) {
  if (spec.parts.empty()) throw std::invalid_argument("crossValidate: no training configuration");
  if (trainingItems.size() != testItems.size())
    throw std::invalid_argument("crossValidate: training and test items differ in number");
  if (spec.analyseMisses && spec.parts.size() != 1)
    throw std::invalid_argument("crossValidate: the miss analysis needs a chain of one cascade");
  CrossValidationResult out;
  out.frames.resize(testItems.size());
  if (spec.analyseMisses) out.positives.resize(testItems.size());
  double detectMs = 0;
  std::size_t detected = 0;
  for (const Fold& fold : folds) {
    std::string name;
    for (const auto& g : fold.testGroups) name += (name.empty() ? "" : "+") + g;
    const std::string shortName =
        fold.testGroups.size() > 2 ? fold.testGroups.front() + " and " + std::to_string(fold.testGroups.size() - 1) + " more drives" : name;
    std::vector<Detector> detectors;
    std::vector<CascadeSummary> parts;
    try {
      for (const TrainingConfig& part : spec.parts) {
        bool cached = false;
        FoldModel source;
        TrainingReport report;
        const auto t0 = std::chrono::steady_clock::now();
        Cascade c = trainOrLoad(part, trainingItems, fold.train, cacheDir, spec.trainingLabels, progress, &report, &cached, &source);
        out.trainSeconds += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        out.cachedFolds += cached ? 1 : 0;
        out.cachedTrainSeconds += cached ? source.trainSeconds : 0;
        out.models.emplace(source.key, source);
        if (spec.keepStages > 0) c = firstStages(std::move(c), spec.keepStages);
        parts.push_back(summarizeCascade(c));
        detectors.emplace_back(std::move(c));
      }
    } catch (const std::runtime_error& e) {
      out.failures.push_back("fold " + name + ": " + e.what());
      if (log) log("fold " + shortName + ": not trained (counted as detecting nothing): " + e.what());
      for (std::size_t i : fold.test) {
        out.frames[i] = frameOutcome({}, matchDetections({}, testItems[i].labels, match));
        if (spec.analyseMisses) out.positives[i] = untrainedOutcomes(testItems[i].labels, match);
      }
      if (spec.scoreTrainingItems)
        for (std::size_t i : fold.train) {
          out.trainingFrames.push_back(frameOutcome({}, matchDetections({}, testItems[i].labels, match)));
          if (spec.analyseMisses) out.trainingPositives.push_back(untrainedOutcomes(testItems[i].labels, match));
        }
      continue;
    }
    std::vector<const Detector*> chain;
    for (const Detector& d : detectors) chain.push_back(&d);
    const EvalOutcome eval = evaluateChain(chain, testItems, fold.test, match, setup);
    for (std::size_t k = 0; k < fold.test.size(); ++k) out.frames[fold.test[k]] = eval.frames[k];
    // The analysis detects on its own; it must see exactly what the evaluation saw.
    const auto explain = [&](const DatasetItem& item, const StackMatch& evaluated) {
      FrameMissAnalysis a = analyseMisses(detectors.front(), item.stack, item.labels, match, setup);
      if (a.match.hits != evaluated.hits || a.match.falseAlarms != evaluated.falseAlarms)
        throw std::logic_error("crossValidate: the miss analysis detected differently from the evaluation on " + item.id);
      return std::move(a.positives);
    };
    if (spec.analyseMisses)
      for (std::size_t k = 0; k < fold.test.size(); ++k)
        out.positives[fold.test[k]] = explain(testItems[fold.test[k]], eval.matches[k]);
    out.summaries.push_back(parts.size() == 1 ? parts.front() : combineSummaries(parts));
    detectMs += eval.msPerStack * static_cast<double>(fold.test.size());
    detected += fold.test.size();
    std::size_t trainHits = 0, trainFalseAlarms = 0, trainPositives = 0;
    if (spec.scoreTrainingItems) {
      const EvalOutcome own = evaluateChain(chain, testItems, fold.train, match, setup);
      out.trainingFrames.insert(out.trainingFrames.end(), own.frames.begin(), own.frames.end());
      if (spec.analyseMisses)
        for (std::size_t k = 0; k < fold.train.size(); ++k)
          out.trainingPositives.push_back(explain(testItems[fold.train[k]], own.matches[k]));
      trainHits = own.counts.hits;
      trainFalseAlarms = own.counts.falseAlarms;
      trainPositives = own.counts.positives;
    }
    if (log) {
      char line[256];
      std::snprintf(line, sizeof line, "fold %s: %zu train / %zu test items, %zu hits, %zu false alarms, %zu positives",
                    shortName.c_str(), fold.train.size(), fold.test.size(), eval.counts.hits, eval.counts.falseAlarms,
                    eval.counts.positives);
      std::string text = line;
      if (spec.scoreTrainingItems) {
        std::snprintf(line, sizeof line, "; on its training items %zu hits, %zu false alarms, %zu positives", trainHits,
                      trainFalseAlarms, trainPositives);
        text += line;
      }
      log(text);
    }
  }
  out.msPerStack = detected ? detectMs / static_cast<double>(detected) : 0.0;
  return out;
}

}  // namespace fusedet::boosting
