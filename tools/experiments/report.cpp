// SPDX-License-Identifier: Apache-2.0
#include "report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <set>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/layer_sources.h"

namespace fusedet::tools::experiments {
namespace {
using nlohmann::json;

std::string num(double v, int decimals = 2) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

json orNull(const std::optional<double>& v) { return v ? json(*v) : json(nullptr); }

json estimateJson(const Estimate& e) {
  json j{{"value", orNull(e.value)}};
  if (e.interval)
    j["ci95"] = {e.interval->lo, e.interval->hi};
  else
    j["ci95"] = nullptr;
  return j;
}

const ConfigResult* find(const ExperimentReport& r, const std::string& cls, const std::string& config) {
  for (const ConfigResult& c : r.results)
    if (c.className == cls && c.config == config) return &c;
  return nullptr;
}

void table(std::ostringstream& md, const std::vector<std::string>& header,
           const std::vector<std::vector<std::string>>& body) {
  md << "|";
  for (const auto& h : header) md << " " << h << " |";
  md << "\n|";
  for (std::size_t i = 0; i < header.size(); ++i) md << (i == 0 ? "---" : "---:") << "|";
  md << "\n";
  for (const auto& line : body) {
    md << "|";
    for (const auto& cell : line) md << " " << cell << " |";
    md << "\n";
  }
  md << "\n";
}

std::string captionOf(const std::string& config) {
  for (const ConfigInfo& i : paperConfigs())
    if (i.config == config) return i.caption;
  return config;
}

}  // namespace

std::string formatEstimate(const Estimate& e, int decimals) {
  std::string s = boosting::formatMeasure(e.value, decimals);
  if (e.value && e.interval) s += " [" + num(e.interval->lo, decimals) + ", " + num(e.interval->hi, decimals) + "]";
  return s;
}

const std::vector<ConfigInfo>& paperConfigs() {
  static const std::vector<ConfigInfo> c = {
      {"all", "Tab. 2: all layers (red, green, blue, intensity, hue distance, distance, remission), features a-j"},
      {"no_corners", "Tab. 3: all layers without the corner-like features (a-f only)"},
      {"laser", "Tab. 4: laser only (distance, remission)"},
      {"camera", "Tab. 5: camera only (intensity, hue distance)"},
      {"four", "Tab. 6: hue distance, intensity, distance, remission"},
      {"and", "Tab. 7: laser-only AND camera-only cascade (Tab. 4 AND Tab. 5; a detection must pass both)"},
      {"all_neural", "issue 30: all layers and the network's score layers (neural_person, neural_bicycle, neural_car), features a-j"},
      {"neural", "issue 30: the network's score layers alone, features a-j"},
  };
  return c;
}

std::vector<std::string> orderedLayers(const std::map<std::string, double>& shares) {
  const std::vector<std::string> paper = {std::string(layer::kRed),         std::string(layer::kGreen),
                                          std::string(layer::kBlue),        std::string(layer::kHueDistance),
                                          std::string(layer::kIntensity),   std::string(layer::kDistance),
                                          std::string(layer::kRemission)};
  std::vector<std::string> out;
  for (const auto& l : paper)
    if (shares.count(l)) out.push_back(l);
  for (const auto& [l, s] : shares)
    if (std::find(paper.begin(), paper.end(), l) == paper.end()) out.push_back(l);
  return out;
}

std::vector<std::string> orderedSources(const std::set<std::string>& sources) {
  std::vector<std::string> out;
  for (const auto s : {fusion::LayerSource::camera, fusion::LayerSource::laser, fusion::LayerSource::network,
                       fusion::LayerSource::unknown})
    if (sources.count(fusion::toString(s))) out.push_back(fusion::toString(s));
  return out;
}

std::string weightShareChartName(const std::string& cls, const std::string& config) {
  return config == "all" ? "weight_share_" + cls + ".png" : "weight_share_" + config + "_" + cls + ".png";
}

std::string renderMarkdown(const ExperimentReport& r) {
  std::ostringstream md;
  md << "# " << r.title << "\n\n";
  md << "Produced by `" << r.command << "` in " << num(r.totalSeconds / 60.0, 1) << " min";
  if (r.loadAverage >= 0) md << " (load average " << num(r.loadAverage, 1) << " at the end, shared 2-core machine)";
  md << "; fold cascades: " << num(r.trainSeconds / 60.0, 1) << " min of training in this run";
  if (r.cachedTrainSeconds > 0)
    md << ", and " << num(r.cachedTrainSeconds / 60.0, 1)
       << " min recorded in the cached ones' model files (their training when they were made)";
  md << ". Cross-drive validation of the experiments of Klein, Schulz, Frintrop, \"Boosting with a Joint "
        "Feature Pool from Different Sensors\" (Tab. 2-7, Fig. 7): every fold tests on drives its cascades "
        "never saw. `results.json` holds the same numbers.\n\n";
  md << "## Data and protocol\n\n" << r.dataDescription << "\n\n";
  {
    std::vector<std::vector<std::string>> body;
    for (const ClassCounts& c : r.counts)
      body.push_back({c.className, std::to_string(c.positives), std::to_string(c.ignoredLabels),
                      std::to_string(c.objects), std::to_string(c.frames), std::to_string(c.drivesWithPositives)});
    table(md,
          {"class", "positives (moderate)", "ignored labels",
           "distinct objects among the positives (KITTI tracking ids of drives 0005 / 0009 count once)",
           "frames with a positive", "drives with a positive"},
          body);
  }
  md << "Evaluation: the KITTI object devkit's 2D rules (fusedet/boost/evaluation.h). A detection hits a "
        "label at the devkit's minimum overlap, IoU >= 0.7 for car and >= 0.5 for person and bike (unless the "
        "settings' \"hit overlap\" row names an override); DontCare absorbs a detection that lies inside "
        "it by that share of its area. Positives are KITTI \"moderate\": box height >= 25 px, occlusion <= 1, "
        "truncation <= 0.3 (the tracking-label drives 0005 and 0009 store truncation levels 0/1/2: "
        "level 0 passes, levels 1 and 2 do not). Labels of the class below moderate and of the "
        "neighbouring class (Van for car, Person_sitting for person) are ignored: a detection on them "
        "counts neither way. Truck, Tram and Misc are "
        "false alarms; detections lower than 25 px are ignored. Precision without any detection is "
        "undefined (null), never 1. F is measured at the operating point (every detection the "
        "cascade outputs after grouping); AP interpolates precision at 40 recall points (KITTI since "
        "2019; 11 points before) over the ranking by score (= grouped hits), which ends at the "
        "operating point, so AP <= the area the detector reaches. Intervals: 95 % percentile "
        "bootstrap over frames (fixed seed), all folds pooled.\n\n";
  if (!r.settings.empty()) {
    md << "## Settings\n\n";
    std::vector<std::vector<std::string>> body;
    for (const auto& [k, v] : r.settings) body.push_back({k, "`" + v + "`"});
    table(md, {"setting", "value"}, body);
  }
  if (!r.goals.empty()) {
    md << "## Goals (issue 15), cross-drive\n\n";
    std::vector<std::vector<std::string>> body;
    for (const Goal& g : r.goals) {
      const bool met = g.measured.value && *g.measured.value >= g.target;
      body.push_back({g.className, g.text, formatEstimate(g.measured), met ? "met" : "**not met**"});
    }
    table(md, {"class", "goal", "measured F [95 % CI]", ""}, body);
  }
  md << "## Results per class (pooled over folds)\n\n"
        "Length: weak classifiers (stumps) per cascade, mean over folds (AND: both cascades). "
        "ms per stack: detection on one test stack, one thread.\n\n";
  for (const std::string& cls : r.classes) {
    std::vector<std::vector<std::string>> body;
    for (const ConfigResult& c : r.results) {
      if (c.className != cls) continue;
      body.push_back({c.config, formatEstimate(c.f), formatEstimate(c.ap), boosting::formatMeasure(c.counts.recall()),
                      boosting::formatMeasure(c.counts.precision()),
                      std::to_string(c.counts.hits) + " / " + std::to_string(c.counts.falseAlarms) + " / " +
                          std::to_string(c.counts.misses),
                      c.trained ? num(c.meanLength, 0) : "-", num(c.msPerStack, 1),
                      c.trained ? num(c.trainSeconds, 0) + (c.cachedFolds ? " (" + std::to_string(c.cachedFolds) +
                                                                                " cached, " + num(c.cachedTrainSeconds, 0) +
                                                                                " when made)"
                                                                          : "")
                                : "-",
                      c.failures.empty() ? "" : std::to_string(c.failures.size())});
    }
    if (body.empty()) continue;
    md << "### " << cls << "\n\n";
    table(md, {"configuration", "F [95 % CI]", "AP [95 % CI]", "recall", "precision", "hits / false alarms / misses",
               "length", "ms per stack", "training [s]", "untrained folds"},
          body);
    md << "![precision-recall " << cls << "](pr_" << cls << ".png)\n\n";
  }
  {
    std::vector<std::string> lines;
    for (const ConfigResult& c : r.results) {
      if (!c.trained && !c.description.empty()) lines.push_back("- `" + c.config + "` (" + c.className + "): " + c.description);
      else if (c.trained) lines.push_back("- `" + c.config + "`: " + (c.description.empty() ? captionOf(c.config) : c.description));
    }
    std::sort(lines.begin(), lines.end());
    lines.erase(std::unique(lines.begin(), lines.end()), lines.end());
    md << "Configurations:\n\n";
    for (const auto& l : lines) md << l << "\n";
    md << "\n";
  }
  std::vector<std::string> failures;
  for (const ConfigResult& c : r.results)
    for (const auto& f : c.failures) failures.push_back(c.className + " / " + c.config + ", " + f);
  if (!failures.empty()) {
    md << "### Folds that could not be trained (they count as detecting nothing)\n\n";
    for (const auto& f : failures) md << "- " << f << "\n";
    md << "\n";
  }

  md << "## The paper's claims, judged with paired bootstrap intervals\n\n"
        "Difference of F (and AP) between the two configurations on the same resampled frames. "
        "\"holds\": the 95 % interval of the difference lies above 0; \"contradicted\": below 0; "
        "\"not shown\": it contains 0 (a tie is not a win).\n\n";
  {
    std::vector<std::vector<std::string>> body;
    for (const Claim& c : r.claims)
      body.push_back({c.className, c.text, formatEstimate(c.fDifference), "**" + c.verdict + "**",
                      formatEstimate(c.apDifference), c.apVerdict});
    if (!body.empty())
      table(md, {"class", "claim", "F difference [95 % CI]", "verdict (F)", "AP difference [95 % CI]", "verdict (AP)"},
            body);
  }
  if (!r.learning.empty()) {
    md << "## Learning curves (F against the amount of training data)\n\n"
          "Configuration `all` per class. Each fold keeps its held-out drive(s) and trains on a seeded "
          "random subset of its training data (nested: a larger subset contains the smaller): a number of "
          "its training drives, or of its training frames taken until they hold at least N positives of "
          "the class (the drives are very unequal); pooled over folds. Every point is also scored on the "
          "folds' own training frames (same detection, same KITTI rules; intervals over (fold, frame) "
          "pairs). High training F with low held-out F that closes as data grows: data-limited (variance); "
          "low training F: the method or its capacity limits (bias). Per-fold counts are what each fold "
          "really trained on: positives (moderate), distinct objects among them (a KITTI tracking id of "
          "drives 0005 / 0009 counts once however many frames show it; every other label once), drives, "
          "frames.";
    if (!r.learningFolds.empty()) md << " Folds: " << r.learningFolds << ".";
    md << "\n\n";
    const auto hfm = [](const boosting::Counts& c) {
      return std::to_string(c.hits) + " / " + std::to_string(c.falseAlarms) + " / " + std::to_string(c.misses);
    };
    const auto perFold = [](const LearningPoint& p, std::size_t boosting::TrainingSetCount::*field) {
      std::string t;
      for (const auto& c : p.perFold) t += (t.empty() ? "" : " / ") + std::to_string(c.*field);
      return t.empty() ? std::string("-") : t;
    };
    const auto trained = [&](const LearningPoint& p, const Estimate& e) {
      return p.trainingScored ? formatEstimate(e) : std::string("-");
    };
    for (const std::string axis : {"drives", "positives"}) {
      std::vector<std::vector<std::string>> body;
      for (const LearningPoint& p : r.learning) {
        if (p.axis != axis) continue;
        std::vector<std::string> row = {p.className};
        if (axis == "drives")
          row.push_back(std::to_string(p.drives));
        else
          row.push_back(p.requested ? std::to_string(p.requested) : "all");
        row.insert(row.end(), {perFold(p, &boosting::TrainingSetCount::positives),
                               perFold(p, &boosting::TrainingSetCount::objects),
                               perFold(p, &boosting::TrainingSetCount::groups),
                               perFold(p, &boosting::TrainingSetCount::items), formatEstimate(p.f),
                               formatEstimate(p.ap), hfm(p.counts), trained(p, p.trainingF), trained(p, p.trainingAp),
                               p.trainingScored ? hfm(p.trainingCounts) : "-"});
        body.push_back(std::move(row));
      }
      if (body.empty()) continue;
      md << (axis == "drives" ? "### Over training drives\n\n" : "### Over training positives\n\n");
      std::vector<std::string> head = {"class", axis == "drives" ? "training drives per fold" : "positives asked per fold",
                                       "positives per fold", "distinct objects per fold", "drives per fold",
                                       "frames per fold", "held-out F [95 % CI]", "held-out AP [95 % CI]",
                                       "held-out hits / FA / misses", "training F [95 % CI]", "training AP [95 % CI]",
                                       "training hits / FA / misses"};
      table(md, head, body);
    }
    for (const std::string& cls : r.classes) md << "![learning curve " << cls << "](learning_" << cls << ".png)\n";
    md << "\n";
  }

  if (!r.sweep.empty()) {
    md << "## Stage count and grouping sweep\n\n"
          "Configuration `all` per class: every fold's trained cascade cut to its first N stages (the cascade "
          "training with a stage limit of N gives: stages are trained in order with per-stage seeds) and its "
          "hits grouped with the given minimum of neighbours; pooled over folds. Every row is measured on the "
          "same held-out frames, so picking the best row here is a choice made on the test frames: choose on "
          "one fold design and confirm on another.\n\n";
    std::vector<std::vector<std::string>> body;
    for (const SweepPoint& p : r.sweep) {
      char stages[64];
      std::snprintf(stages, sizeof stages, "%.1f / %.1f", p.meanStages, p.meanLength);
      body.push_back({p.className, std::to_string(p.stages), std::to_string(p.minNeighbors), stages,
                      formatEstimate(p.f), formatEstimate(p.ap),
                      std::to_string(p.counts.hits) + " / " + std::to_string(p.counts.falseAlarms) + " / " +
                          std::to_string(p.counts.misses)});
    }
    table(md, {"class", "stages kept (at most)", "min neighbours", "mean stages / stumps", "F [95 % CI]", "AP [95 % CI]",
               "hits / false alarms / misses"},
          body);
  }

  if (!r.misses.empty()) {
    md << "## Where the missed positives are lost\n\n"
          "Every positive of the `all` configuration's held-out frames that no detection hits (and, in the rows "
          "\"on its own training frames\", every (fold, positive) pair of the learning curve's folds that the fold's "
          "cascade misses on the frames it was trained on), classified by the first step that lost it (boosting::analyseMisses, miss_analysis.h), with the class's hit overlap "
          "(IoU below): **scan geometry** - no window the scan visits (window aspect, minimum size, scale step, "
          "position step, image border) reaches that IoU with it; **grouping** - such a window is accepted by the "
          "cascade but grouping drops it (too few neighbours, inside a bigger group) or merges it into a detection "
          "that misses the object; **localisation** - no such window is accepted, but a detection overlaps the "
          "object with IoU >= the localisation limit (badly placed: also a false alarm); **cascade** - every such "
          "window is rejected by the cascade.\n\n";
    for (const MissResult& m : r.misses) {
      const boosting::MissBreakdown& b = m.breakdown;
      char head[256];
      std::snprintf(head, sizeof head,
                    "%s / %s: %zu of %zu positives missed (hit IoU >= %.2f, min neighbours %d, localisation IoU >= %.2f)",
                    m.className.c_str(), m.config.c_str(), b.allMisses, b.allPositives, m.minIou, m.minNeighbors,
                    m.localisationIou);
      md << "### " << head << "\n\n";
      std::vector<std::vector<std::string>> body;
      for (boosting::MissCause c : boosting::kMissCauses) {
        const std::size_t k = static_cast<std::size_t>(c);
        if (c == boosting::MissCause::kUntrained && b.total[k] == 0) continue;
        char share[32];
        std::snprintf(share, sizeof share, "%.0f %%", b.allMisses ? 100.0 * double(b.total[k]) / double(b.allMisses) : 0.0);
        body.push_back({boosting::missCauseName(c), std::to_string(b.total[k]), share, std::to_string(b.nearDetection[k])});
      }
      table(md, {"cause", "misses", "share of misses", "of them with a detection at IoU >= the localisation limit"},
            body);
      body.clear();
      for (std::size_t k = 0; k < b.bucketNames.size(); ++k) {
        std::vector<std::string> row{b.bucketGroup[k] + ": " + b.bucketNames[k], std::to_string(b.positives[k]),
                                     std::to_string(b.misses[k])};
        char recall[32];
        if (b.positives[k] > 0)
          std::snprintf(recall, sizeof recall, "%.2f", double(b.positives[k] - b.misses[k]) / double(b.positives[k]));
        else
          std::snprintf(recall, sizeof recall, "null");
        row.emplace_back(recall);
        for (boosting::MissCause c : boosting::kMissCauses)
          if (c != boosting::MissCause::kUntrained || b.total[static_cast<std::size_t>(c)] > 0)
            row.push_back(std::to_string(b.byCause[static_cast<std::size_t>(c)][k]));
        body.push_back(std::move(row));
      }
      std::vector<std::string> header{"objects", "positives", "misses", "recall"};
      for (boosting::MissCause c : boosting::kMissCauses)
        if (c != boosting::MissCause::kUntrained || b.total[static_cast<std::size_t>(c)] > 0)
          header.push_back(boosting::missCauseName(c));
      table(md, header, body);
      md << "Grouping losses:";
      for (std::size_t g = 1; g < b.groupingLosses.size(); ++g)
        md << (g > 1 ? "," : "") << " " << boosting::groupingLossName(static_cast<boosting::GroupingLoss>(g)) << " "
           << b.groupingLosses[g];
      char iouText[32];
      std::snprintf(iouText, sizeof iouText, "IoU >= %.2f", m.minIou);
      md << ". Too few neighbours, by the largest group an accepted window with " << iouText << " fell in:";
      for (std::size_t g = 0; g < b.tooFewByGroupSize.size(); ++g)
        if (b.tooFewByGroupSize[g] > 0) md << " " << g << " member" << (g == 1 ? "" : "s") << ": " << b.tooFewByGroupSize[g] << ";";
      md << " cascade misses by the stage that rejected the deepest window with " << iouText << ":";
      bool any = false;
      for (std::size_t s = 0; s < b.rejectedAtStage.size(); ++s)
        if (b.rejectedAtStage[s] > 0) {
          md << (any ? "," : "") << " stage " << s + 1 << ": " << b.rejectedAtStage[s];
          any = true;
        }
      md << (any ? ".\n\n" : " none.\n\n");
    }
  }

  const auto weightShares = [&](const std::string& config, const std::string& heading) {
    std::vector<const ConfigResult*> results;
    std::map<std::string, double> allLayers;
    for (const std::string& cls : r.classes)
      if (const ConfigResult* c = find(r, cls, config); c && !c->layerWeightShare.empty()) {
        results.push_back(c);
        for (const auto& [l, s] : c->layerWeightShare) allLayers[l] += s;
      }
    if (results.empty()) return;
    md << heading << "Cascades of configuration `" << config
       << "`, all folds together. The weight of a stump is |right - left|: the amount it moves the stage sum "
          "between its two sides. Shares are weights summed per layer, divided by the total; the second "
          "table sums them per source (fusedet/fusion/layer_sources.h: camera = red, green, blue, intensity, "
          "hue distance; laser = distance, remission; network = the network's score layers neural_*).\n\n";
    const std::vector<std::string> layers = orderedLayers(allLayers);
    std::vector<std::string> header{"class"};
    header.insert(header.end(), layers.begin(), layers.end());
    header.push_back("corner features");
    std::vector<std::vector<std::string>> body, sourceBody;
    std::set<std::string> sources;
    for (const ConfigResult* c : results)
      for (const auto& [src, s] : fusion::sharesBySource(c->layerWeightShare)) sources.insert(src);
    const std::vector<std::string> sourceOrder = orderedSources(sources);
    for (const ConfigResult* c : results) {
      std::vector<std::string> line{c->className};
      for (const auto& l : layers) {
        const auto it = c->layerWeightShare.find(l);
        line.push_back(num(it == c->layerWeightShare.end() ? 0.0 : 100 * it->second, 1) + " %");
      }
      line.push_back(num(100 * c->cornerShare, 0) + " %");
      body.push_back(line);
      const auto bySource = fusion::sharesBySource(c->layerWeightShare);
      std::vector<std::string> sl{c->className};
      for (const auto& src : sourceOrder) {
        const auto it = bySource.find(src);
        sl.push_back(num(it == bySource.end() ? 0.0 : 100 * it->second, 1) + " %");
      }
      sourceBody.push_back(sl);
    }
    table(md, header, body);
    std::vector<std::string> sourceHeader{"class"};
    sourceHeader.insert(sourceHeader.end(), sourceOrder.begin(), sourceOrder.end());
    table(md, sourceHeader, sourceBody);
    for (const ConfigResult* c : results)
      md << "![weight share " << c->className << "](" << weightShareChartName(c->className, config) << ")\n";
    md << "\n";
  };
  weightShares("all", "## Weight share by layer (paper Fig. 7)\n\n");
  weightShares("all_neural", "## Weight share by layer with the network's score layers (issue 30)\n\n");
  if (!r.notes.empty()) {
    md << "## Notes\n\n";
    for (const auto& n : r.notes) md << "- " << n << "\n";
    md << "\n";
  }
  return md.str();
}

json toJson(const ExperimentReport& r) {
  json j;
  j["title"] = r.title;
  j["command"] = r.command;
  j["data"] = r.dataDescription;
  j["folds"] = r.folds;
  j["stacks"] = r.stacks;
  j["total_seconds"] = r.totalSeconds;
  j["train_seconds"] = r.trainSeconds;
  j["cached_train_seconds"] = r.cachedTrainSeconds;
  j["load_average"] = r.loadAverage;
  j["settings"] = r.settings;
  j["notes"] = r.notes;
  j["counts"] = json::array();
  for (const ClassCounts& c : r.counts)
    j["counts"].push_back({{"class", c.className}, {"positives", c.positives}, {"ignored_labels", c.ignoredLabels},
                           {"distinct_objects", c.objects}, {"frames", c.frames},
                           {"drives_with_positives", c.drivesWithPositives}});
  j["results"] = json::array();
  for (const ConfigResult& c : r.results) {
    json curve = json::array();
    for (const auto& p : c.curve)
      curve.push_back({{"threshold", p.threshold}, {"recall", p.recall}, {"precision", p.precision},
                       {"hits", p.hits}, {"false_alarms", p.falseAlarms}});
    json e{{"class", c.className},
           {"config", c.config},
           {"description", c.description},
           {"trained", c.trained},
           {"layers", c.layers},
           {"f_measure", estimateJson(c.f)},
           {"average_precision", estimateJson(c.ap)},
           {"recall", orNull(c.counts.recall())},
           {"precision", orNull(c.counts.precision())},
           {"hits", c.counts.hits},
           {"false_alarms", c.counts.falseAlarms},
           {"misses", c.counts.misses},
           {"positives", c.counts.positives},
           {"ignored_detections", c.counts.ignored},
           {"stacks", c.counts.stacks},
           {"ms_per_stack", c.msPerStack},
           {"pr_curve", curve},
           {"failures", c.failures}};
    if (c.trained) {
      e["mean_length"] = c.meanLength;
      e["mean_stages"] = c.meanStages;
      e["folds"] = c.folds;
      e["cached_folds"] = c.cachedFolds;
      e["train_seconds"] = c.trainSeconds;
      e["cached_train_seconds"] = c.cachedTrainSeconds;
      e["layer_weight_share"] = c.layerWeightShare;
      e["source_weight_share"] = fusion::sharesBySource(c.layerWeightShare);
      e["corner_share"] = c.cornerShare;
    }
    j["results"].push_back(std::move(e));
  }
  j["claims"] = json::array();
  for (const Claim& c : r.claims)
    j["claims"].push_back({{"class", c.className}, {"key", c.key}, {"claim", c.text}, {"lhs", c.lhs}, {"rhs", c.rhs},
                           {"f_difference", estimateJson(c.fDifference)}, {"verdict", c.verdict},
                           {"ap_difference", estimateJson(c.apDifference)}, {"ap_verdict", c.apVerdict}});
  j["learning_curve_folds"] = r.learningFolds;
  j["learning_curve"] = json::array();
  for (const LearningPoint& p : r.learning) {
    json e{{"class", p.className}, {"axis", p.axis}, {"f_measure", estimateJson(p.f)},
           {"average_precision", estimateJson(p.ap)}, {"hits", p.counts.hits},
           {"false_alarms", p.counts.falseAlarms}, {"misses", p.counts.misses}};
    if (p.axis == "drives")
      e["drives"] = p.drives;
    else
      e["positives_asked"] = p.requested ? json(p.requested) : json("all");
    e["folds"] = json::array();
    for (const auto& c : p.perFold)
      e["folds"].push_back({{"frames", c.items}, {"positives", c.positives}, {"distinct_objects", c.objects},
                            {"drives", c.groups}});
    if (p.trainingScored)
      e["training"] = {{"f_measure", estimateJson(p.trainingF)}, {"average_precision", estimateJson(p.trainingAp)},
                       {"hits", p.trainingCounts.hits}, {"false_alarms", p.trainingCounts.falseAlarms},
                       {"misses", p.trainingCounts.misses}};
    j["learning_curve"].push_back(std::move(e));
  }
  j["stage_sweep"] = json::array();
  for (const SweepPoint& p : r.sweep)
    j["stage_sweep"].push_back({{"class", p.className}, {"stages", p.stages}, {"min_neighbors", p.minNeighbors},
                                {"mean_stages", p.meanStages}, {"mean_stumps", p.meanLength},
                                {"f_measure", estimateJson(p.f)}, {"average_precision", estimateJson(p.ap)},
                                {"hits", p.counts.hits}, {"false_alarms", p.counts.falseAlarms},
                                {"misses", p.counts.misses}});
  j["miss_analysis"] = json::array();
  for (const MissResult& m : r.misses) {
    const boosting::MissBreakdown& b = m.breakdown;
    json causes = json::object(), buckets = json::array(), grouping = json::object();
    for (boosting::MissCause c : boosting::kMissCauses) {
      const std::size_t k = static_cast<std::size_t>(c);
      causes[boosting::missCauseName(c)] = {{"misses", b.total[k]}, {"with_near_detection", b.nearDetection[k]}};
    }
    for (std::size_t k = 0; k < b.bucketNames.size(); ++k) {
      json byCause = json::object();
      for (boosting::MissCause c : boosting::kMissCauses)
        byCause[boosting::missCauseName(c)] = b.byCause[static_cast<std::size_t>(c)][k];
      buckets.push_back({{"group", b.bucketGroup[k]}, {"bucket", b.bucketNames[k]}, {"positives", b.positives[k]},
                         {"misses", b.misses[k]}, {"by_cause", byCause}});
    }
    for (std::size_t g = 1; g < b.groupingLosses.size(); ++g)
      grouping[boosting::groupingLossName(static_cast<boosting::GroupingLoss>(g))] = b.groupingLosses[g];
    j["miss_analysis"].push_back({{"class", m.className}, {"config", m.config}, {"positives", b.allPositives},
                                  {"misses", b.allMisses}, {"min_neighbors", m.minNeighbors},
                                  {"localisation_iou", m.localisationIou}, {"min_iou", m.minIou}, {"causes", causes}, {"buckets", buckets},
                                  {"grouping_losses", grouping}, {"cascade_rejected_at_stage", b.rejectedAtStage},
                                  {"too_few_neighbours_by_group_size", b.tooFewByGroupSize}});
  }
  j["goals"] = json::array();
  for (const Goal& g : r.goals)
    j["goals"].push_back({{"class", g.className}, {"goal", g.text}, {"target", g.target},
                          {"f_measure", estimateJson(g.measured)},
                          {"met", g.measured.value.has_value() && *g.measured.value >= g.target}});
  return j;
}

cv::Mat weightShareChart(const std::string& title, const std::map<std::string, double>& shares) {
  const std::vector<std::string> layers = orderedLayers(shares);
  const int barW = 80, gap = 16, left = 60, top = 50, plotH = 260, bottom = 50;
  const int width = std::max(360, left + static_cast<int>(layers.size()) * (barW + gap) + gap);
  cv::Mat img(top + plotH + bottom, width, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(img, title, {left, 30}, font, 0.6, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  double maxShare = 0;
  for (const auto& [l, s] : shares) maxShare = std::max(maxShare, s);
  // Axis up to the next 10 %.
  const double axis = std::max(0.1, std::ceil(maxShare * 10 - 1e-9) / 10);
  const int y0 = top + plotH;
  for (int t = 0; t <= static_cast<int>(std::lround(axis * 10)); ++t) {
    const int y = y0 - static_cast<int>(std::lround(plotH * (t / 10.0) / axis));
    cv::line(img, {left - 4, y}, {width - gap, y}, cv::Scalar(225, 225, 225), 1);
    cv::putText(img, std::to_string(t * 10) + "%", {8, y + 4}, font, 0.4, cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
  }
  cv::line(img, {left - 4, y0}, {width - gap, y0}, cv::Scalar(0, 0, 0), 1);
  // Camera layers blue-ish, laser layers orange, as sensor groups.
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const double s = shares.at(layers[i]);
    const int x = left + gap / 2 + static_cast<int>(i) * (barW + gap);
    const int h = static_cast<int>(std::lround(plotH * s / axis));
    const bool laser = layers[i] == layer::kDistance || layers[i] == layer::kRemission;
    const cv::Scalar colour = laser ? cv::Scalar(40, 130, 230) : cv::Scalar(190, 120, 40);
    cv::rectangle(img, cv::Rect(x, y0 - h, barW, h), colour, cv::FILLED);
    cv::putText(img, num(100 * s, 1), {x + 14, y0 - h - 6}, font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
    std::string name = layers[i] == layer::kHueDistance ? "hue dist" : layers[i];
    cv::putText(img, name, {x + 2, y0 + 20}, font, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  cv::putText(img, "camera layers", {left, y0 + 42}, font, 0.4, cv::Scalar(190, 120, 40), 1, cv::LINE_AA);
  cv::putText(img, "laser layers", {left + 130, y0 + 42}, font, 0.4, cv::Scalar(40, 130, 230), 1, cv::LINE_AA);
  return img;
}

cv::Mat lineChart(const std::string& title, const std::string& xLabel, const std::string& yLabel, double xMax,
                  const std::vector<Series>& series) {
  const int left = 60, top = 40, plotW = 460, plotH = 300, right = 190, bottom = 50;
  cv::Mat img(top + plotH + bottom, left + plotW + right, CV_8UC3, cv::Scalar(255, 255, 255));
  const auto font = cv::FONT_HERSHEY_SIMPLEX;
  cv::putText(img, title, {left, 26}, font, 0.55, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  const double xm = xMax > 0 ? xMax : 1;
  const auto px = [&](double x, double y) {
    return cv::Point(left + static_cast<int>(std::lround(plotW * std::clamp(x / xm, 0.0, 1.0))),
                     top + plotH - static_cast<int>(std::lround(plotH * std::clamp(y, 0.0, 1.0))));
  };
  for (int t = 0; t <= 10; t += 2) {
    const cv::Point a = px(0, t / 10.0), b = px(xm, t / 10.0);
    cv::line(img, a, b, cv::Scalar(225, 225, 225), 1);
    cv::putText(img, num(t / 10.0, 1), {a.x - 34, a.y + 4}, font, 0.4, cv::Scalar(80, 80, 80), 1, cv::LINE_AA);
    const cv::Point c = px(xm * t / 10.0, 0);
    cv::putText(img, num(xm * t / 10.0, xm > 2 ? 0 : 1), {c.x - 10, c.y + 18}, font, 0.4, cv::Scalar(80, 80, 80), 1,
                cv::LINE_AA);
  }
  cv::rectangle(img, px(0, 1), px(xm, 0), cv::Scalar(0, 0, 0), 1);
  cv::putText(img, xLabel, {left + plotW / 2 - 40, top + plotH + 40}, font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  cv::putText(img, yLabel, {4, top - 8}, font, 0.45, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  static const cv::Scalar colours[] = {{190, 120, 40}, {40, 130, 230}, {60, 170, 60},  {40, 40, 200},
                                       {160, 60, 160}, {30, 30, 30},   {0, 180, 200}, {120, 120, 120}};
  for (std::size_t s = 0; s < series.size(); ++s) {
    const cv::Scalar colour = colours[s % std::size(colours)];
    const auto& pts = series[s].points;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const cv::Point p = px(pts[i].first, pts[i].second);
      cv::circle(img, p, 3, colour, cv::FILLED, cv::LINE_AA);
      if (i > 0) cv::line(img, px(pts[i - 1].first, pts[i - 1].second), p, colour, 2, cv::LINE_AA);
      if (i < series[s].band.size())
        cv::line(img, px(pts[i].first, series[s].band[i].first), px(pts[i].first, series[s].band[i].second), colour, 1);
    }
    const int ly = top + 14 + static_cast<int>(s) * 20;
    cv::line(img, {left + plotW + 14, ly - 4}, {left + plotW + 34, ly - 4}, colour, 2);
    cv::putText(img, series[s].name, {left + plotW + 40, ly}, font, 0.42, cv::Scalar(0, 0, 0), 1, cv::LINE_AA);
  }
  return img;
}

double LearningPoint::meanPositives() const {
  if (perFold.empty()) return 0;
  double sum = 0;
  for (const auto& c : perFold) sum += static_cast<double>(c.positives);
  return sum / static_cast<double>(perFold.size());
}

cv::Mat learningChart(const std::string& cls, const std::vector<LearningPoint>& points) {
  std::vector<cv::Mat> panels;
  for (const std::string axis : {"drives", "positives"}) {
    Series f{"F held out", {}, {}}, ap{"AP held out", {}, {}}, tf{"F training", {}, {}}, tap{"AP training", {}, {}};
    double xMax = 0;
    const auto add = [](Series& se, double x, const Estimate& e) {
      if (!e.value) return;
      se.points.push_back({x, *e.value});
      se.band.push_back(e.interval ? std::make_pair(e.interval->lo, e.interval->hi) : std::make_pair(*e.value, *e.value));
    };
    for (const LearningPoint& p : points) {
      if (p.className != cls || p.axis != axis) continue;
      const double x = axis == "drives" ? static_cast<double>(p.drives) : p.meanPositives();
      xMax = std::max(xMax, x);
      add(f, x, p.f);
      add(ap, x, p.ap);
      if (p.trainingScored) {
        add(tf, x, p.trainingF);
        add(tap, x, p.trainingAp);
      }
    }
    if (f.points.empty()) continue;
    std::vector<Series> drawn;
    for (Series* se : {&f, &ap, &tf, &tap})
      if (!se->points.empty()) drawn.push_back(std::move(*se));
    panels.push_back(lineChart(cls + (axis == "drives" ? ": vs training drives per fold (95% CI)"
                                                       : ": vs training positives per fold (95% CI)"),
                               axis == "drives" ? "training drives" : "training positives (mean of folds)", "F, AP",
                               xMax, drawn));
  }
  if (panels.empty()) return {};
  cv::Mat out;
  cv::hconcat(panels, out);
  return out;
}

void writeReport(const std::filesystem::path& dir, const ExperimentReport& report) {
  std::filesystem::create_directories(dir);
  {
    std::ofstream md(dir / "report.md");
    md << renderMarkdown(report);
    if (!md) throw std::runtime_error((dir / "report.md").string() + ": cannot write");
  }
  std::ofstream js(dir / "results.json");
  js << toJson(report).dump(2) << "\n";
  if (!js) throw std::runtime_error((dir / "results.json").string() + ": cannot write");
}

}  // namespace fusedet::tools::experiments
