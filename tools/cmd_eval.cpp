// SPDX-License-Identifier: Apache-2.0
// fusedet eval: a trained cascade (or the AND of several) on the frames of a data set - recall,
// precision, F-measure, cascade length, weight share per layer (paper Fig. 7), share of corner
// features and detection time, as a markdown table or JSON.

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <memory>
#include <nlohmann/json.hpp>

#include "command.h"
#include "fusedet/fusion/datasets/coco_labels.h"
#include "experiments/report.h"
#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/precision_recall.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;
using experiments::orderedLayers;
using nlohmann::json;

struct EvalOptions {
  std::vector<fs::path> models;
  fs::path data;
  std::string split = "test";
  double trainFraction = 2.0 / 3.0;
  bool json = false;
  fs::path cocoResults;
  double minIou = 0, minHeight = 25, maxTruncation = 0.3;
  int maxOcclusion = 1;
  std::string van = "ignore";
  double scaleFactor = 1.1, step = 2;
  int minNeighbors = 3;
  bool laserExtent = false;
  int threads = 1;
};

std::string pct(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f %%", 100 * v);
  return buf;
}

int runEval(const EvalOptions& o) {
  if (!fs::exists(o.data / "dataset.json"))
    throw std::runtime_error(o.data.string() + ": not a data set (no dataset.json); import KITTI drives with "
                                               "`fusedet import-kitti --out DIR` first");
  std::vector<boosting::Detector> detectors;
  std::vector<boosting::CascadeSummary> summaries;
  for (const fs::path& m : o.models) {
    boosting::Cascade c = boosting::loadModel(m);
    summaries.push_back(boosting::summarizeCascade(c));
    detectors.emplace_back(std::move(c));
  }
  const std::string cls = detectors.front().cascade().className;
  for (const auto& d : detectors)
    if (d.cascade().className != cls)
      throw std::runtime_error(d.cascade().source + ": class '" + d.cascade().className +
                               "' differs from the first model's '" + cls + "'; AND needs one class");

  const std::vector<DatasetEntry> manifest = readDatasetManifest(o.data);
  std::vector<DatasetEntry> entries;
  if (o.split == "all") {
    entries = manifest;
  } else {
    const boosting::Split s = boosting::splitByFrame(manifest, o.trainFraction);
    entries = o.split == "train" ? s.train : s.test;
  }
  // Layers the models read; hue_distance is derived from hue with each model's reference hue.
  std::vector<std::string> layers;
  for (const auto& d : detectors)
    for (const std::string& l : d.cascade().layers) {
      const std::string need = l == "hue_distance" ? "hue" : l;
      if (std::find(layers.begin(), layers.end(), need) == layers.end()) layers.push_back(need);
    }
  std::vector<DatasetItem> items;
  for (const DatasetEntry& e : entries) items.push_back(readDatasetItem(o.data, e.id, layers));

  boosting::MatchConfig match = boosting::matchConfigFor(cls, boosting::parseVanPolicy(o.van), o.minIou);
  match.minHeight = o.minHeight;
  match.maxOcclusion = o.maxOcclusion;
  match.maxTruncation = o.maxTruncation;
  boosting::DetectionSetup setup;
  setup.scan.scaleFactor = o.scaleFactor;
  setup.scan.step = o.step;
  setup.scan.threads = o.threads;
  setup.group.minNeighbors = o.minNeighbors;
  setup.laserExtent.enabled = o.laserExtent;
  std::vector<const boosting::Detector*> chain;
  for (const auto& d : detectors) chain.push_back(&d);
  const boosting::EvalOutcome r = boosting::evaluateChain(chain, items, match, setup);
  const std::optional<double> ap = boosting::averagePrecision(boosting::allFrames(r.frames));
  if (!o.cocoResults.empty()) {
    std::vector<std::pair<std::string, std::vector<Detection>>> perItem;
    for (std::size_t i = 0; i < entries.size(); ++i) perItem.emplace_back(entries[i].id, r.detections[i]);
    std::vector<std::string> manifestIds;
    for (const DatasetEntry& e : manifest) manifestIds.push_back(e.id);
    std::ofstream out(o.cocoResults);
    if (!(out << fusion::cocoResults(manifestIds, perItem).dump() << "\n") || !out.flush())
      throw std::runtime_error(o.cocoResults.string() + ": cannot write");
  }
  const auto orNull = [](const std::optional<double>& v) { return v ? json(*v) : json(nullptr); };
  const boosting::CascadeSummary s = summaries.size() == 1 ? summaries.front() : boosting::combineSummaries(summaries);

  if (o.json) {
    json j;
    j["class"] = cls;
    j["models"] = json::array();
    for (const fs::path& m : o.models) j["models"].push_back(m.string());
    j["data"] = o.data.string();
    j["split"] = o.split;
    j["stacks"] = r.counts.stacks;
    j["recall"] = orNull(r.counts.recall());
    j["precision"] = orNull(r.counts.precision());
    j["f_measure"] = orNull(r.counts.fMeasure());
    j["average_precision"] = orNull(ap);
    j["ap_rule"] = "KITTI 40 recall points";
    j["hits"] = r.counts.hits;
    j["false_alarms"] = r.counts.falseAlarms;
    j["misses"] = r.counts.misses;
    j["positives"] = r.counts.positives;
    j["ignored_detections"] = r.counts.ignored;
    j["length"] = s.length;
    j["split_nodes"] = s.splits;
    j["stages"] = s.stages;
    j["layer_weight_share"] = s.layerWeightShare;
    j["layer_stump_count"] = s.layerCount;
    j["corner_share"] = s.cornerShare();
    j["ms_per_stack"] = r.msPerStack;
    j["windows"] = r.windows;
    j["match"] = {{"min_iou", match.minIou}, {"min_height", match.minHeight}, {"max_occlusion", match.maxOcclusion},
                  {"max_truncation", match.maxTruncation}, {"min_detection_height", match.minDetectionHeight},
                  {"van", o.van}};
    std::cout << j.dump(2) << "\n";
    return 0;
  }
  std::printf("# fusedet eval: %s\n\n", cls.c_str());
  std::printf("Model%s:", o.models.size() > 1 ? "s (AND: a window must pass each)" : "");
  for (const fs::path& m : o.models) std::printf(" `%s`", m.c_str());
  std::printf("\n\nData: `%s`, %s split, %zu stacks. Match (KITTI devkit 2D rules): IoU >= %.2f; labels lower "
              "than %.0f px, occluded more than level %d or truncated more than %.2f are ignored, as are "
              "ignore regions and detections lower than %.0f px; van: %s.\n\n",
              o.data.c_str(), o.split.c_str(), r.counts.stacks, match.minIou, match.minHeight, match.maxOcclusion,
              match.maxTruncation, match.minDetectionHeight, o.van.c_str());
  std::printf("| measure | value |\n|---|---:|\n");
  std::printf("| length (weak classifiers) | %zu |\n| split nodes | %zu |\n| stages | %zu |\n", s.length, s.splits,
              s.stages);
  std::printf("| recall | %s |\n| precision | %s |\n| F-measure | %s |\n| AP (40 recall points) | %s |\n",
              boosting::formatMeasure(r.counts.recall(), 3).c_str(), boosting::formatMeasure(r.counts.precision(), 3).c_str(),
              boosting::formatMeasure(r.counts.fMeasure(), 3).c_str(), boosting::formatMeasure(ap, 3).c_str());
  std::printf("| hits / false alarms / misses | %zu / %zu / %zu |\n", r.counts.hits, r.counts.falseAlarms,
              r.counts.misses);
  std::printf("| positives | %zu |\n| ignored detections | %zu |\n", r.counts.positives, r.counts.ignored);
  std::printf("| corner features | %s |\n| ms per stack | %.1f |\n\n", pct(s.cornerShare()).c_str(), r.msPerStack);
  std::printf("| layer | weight share | split nodes |\n|---|---:|---:|\n");
  for (const std::string& l : orderedLayers(s.layerWeightShare))
    std::printf("| %s | %s | %zu |\n", l.c_str(), pct(s.layerWeightShare.at(l)).c_str(),
                s.layerCount.count(l) ? s.layerCount.at(l) : std::size_t{0});
  return 0;
}

const bool registered = registerCommand(
    "eval", "Evaluate a trained cascade on a data set: recall, precision, F-measure, length, weight share per layer",
    [](CLI::App& app) {
      auto o = std::make_shared<EvalOptions>();
      app.add_option("--model,-m", o->models,
                     "model file (fusedet-cascade JSON); give it twice or more for the AND of the cascades "
                     "(a window must pass each; all of one class)")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("--data", o->data, "data set directory (dataset.json; see docs/dataset-format.md)")->required();
      app.add_option("--coco-results", o->cocoResults,
                     "also write every detection as a COCO results file (image ids as `fusedet dataset export "
                     "--format coco` gives them, COCO's category ids), for COCO-style evaluation tools");
      app.add_option("--split", o->split,
                     "frames to evaluate: test (the last third of each group's frames), train (the first two "
                     "thirds), all")
          ->check(CLI::IsMember({"test", "train", "all"}))
          ->capture_default_str();
      app.add_option("--train-fraction", o->trainFraction, "share of each group's first frames that train")
          ->check(CLI::Range(0.05, 0.95))
          ->capture_default_str();
      app.add_flag("--json", o->json,
                   "print one JSON object (recall, precision, f_measure, length, stages, layer_weight_share, "
                   "layer_stump_count, corner_share, ms_per_stack, counts) instead of markdown");
      app.add_option("--min-iou", o->minIou,
                     "a detection hits a label at IoU >= this; 0 = the KITTI devkit's minimum overlap of the class "
                     "(car 0.7, person and bike 0.5)")
          ->check(CLI::Range(0.0, 1.0))
          ->capture_default_str();
      app.add_option("--min-height", o->minHeight, "labels lower than this [px] are ignored (KITTI moderate: 25)")
          ->capture_default_str();
      app.add_option("--max-occlusion", o->maxOcclusion, "labels occluded more are ignored (KITTI moderate: 1)")
          ->capture_default_str();
      app.add_option("--max-truncation", o->maxTruncation,
                     "labels truncated more are ignored (KITTI moderate: 0.3; tracking labels hold levels 0/1/2, so "
                     "only level 0 passes); < 0 = not checked")
          ->capture_default_str();
      app.add_option("--van", o->van, "a van for the car class: ignore (KITTI's neighbouring class: neither hit nor false alarm), "
                     "negative (false alarm), positive")
          ->check(CLI::IsMember({"ignore", "negative", "positive"}))
          ->capture_default_str();
      app.add_option("--scale-factor", o->scaleFactor, "window scale step")->capture_default_str();
      app.add_option("--step", o->step, "position step in base-window pixels")->capture_default_str();
      app.add_option("--min-neighbors", o->minNeighbors, "grouping: hits a detection needs")->capture_default_str();
      app.add_flag("--laser-extent", o->laserExtent,
                   "after grouping, widen each detection's left and right edges to where its object's cluster in "
                   "the distance layer ends (fusedet/boost/laser_extent.h; default: off)");
      app.add_option("--threads", o->threads, "detection threads (ms per stack is measured with these)")
          ->capture_default_str();
      app.footer(
          "Weight share per layer: each stump weighs |right leaf - left leaf| (how far it moves the stage "
          "sum), summed per layer over all stages and divided by the total (paper Fig. 7).\n"
          "KITTI object devkit 2D rules: DontCare regions absorb a detection lying inside them by >= min-iou "
          "of its area; Van (for car) and Person_sitting (for person) are ignored labels; Truck, Tram and Misc "
          "are false alarms; detections lower than 25 px are ignored. Precision without any detection is "
          "null, not 1; AP interpolates precision at 40 recall points (KITTI since 2019) over the ranking "
          "by score, which ends at the operating point.\n\n"
          "Examples:\n"
          "  fusedet eval -m models/car.json --data /tmp/kitti-ds\n"
          "  fusedet eval -m car_laser.json -m car_camera.json --data ds --json   # AND combination\n"
          "  fusedet eval -m models/person.json --data ds --split all --min-height 40");
      return [o] { return runEval(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
