#include "experiments_report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgproc.hpp>
#include <sstream>
#include <stdexcept>

#include "fusedet/core/layer_stack.h"

namespace fusedet::tools::experiments {
namespace {
using nlohmann::json;

std::string num(double v, int decimals = 2) {
  if (!std::isfinite(v)) return "-";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  return buf;
}

const ConfigResult* find(const ExperimentReport& r, const std::string& cls, const std::string& config) {
  for (const ConfigResult& c : r.results)
    if (c.className == cls && c.config == config) return &c;
  return nullptr;
}

// The rows every results table has, in the paper's order plus our extra columns.
struct Row {
  std::string name;
  std::string (*cell)(const ConfigResult&);
};
const std::vector<Row>& rows() {
  static const std::vector<Row> r = {
      {"length", [](const ConfigResult& c) { return c.trained ? std::to_string(c.length) : std::string("-"); }},
      {"stages", [](const ConfigResult& c) { return c.trained ? std::to_string(c.stages) : std::string("-"); }},
      {"recall", [](const ConfigResult& c) { return num(c.counts.recall()); }},
      {"precision", [](const ConfigResult& c) { return num(c.counts.precision()); }},
      {"F-measure", [](const ConfigResult& c) { return num(c.counts.fMeasure()); }},
      {"hits / false alarms / misses",
       [](const ConfigResult& c) {
         return std::to_string(c.counts.hits) + " / " + std::to_string(c.counts.falseAlarms) + " / " +
                std::to_string(c.counts.misses);
       }},
      {"ms per stack", [](const ConfigResult& c) { return num(c.msPerStack, 1); }},
      {"training time [s]", [](const ConfigResult& c) { return c.trained ? num(c.trainSeconds, 1) : std::string("-"); }},
  };
  return r;
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

// Fewer test positives than this make a comparison a coin toss: the claim is "undecided".
constexpr std::size_t kMinPositivesForClaim = 5;

// A claim "a >= b" on F-measure, with both numbers; null when either was not evaluated.
// verdict: "holds", "does not hold", or "undecided" (too few test positives, or both F are 0).
json compare(const ConfigResult* a, const ConfigResult* b) {
  if (!a || !b) return nullptr;
  const double fa = a->counts.fMeasure(), fb = b->counts.fMeasure();
  const bool undecided = a->counts.positives < kMinPositivesForClaim || (fa == 0 && fb == 0);
  return json{{"lhs", a->config},
              {"rhs", b->config},
              {"lhs_f_measure", fa},
              {"rhs_f_measure", fb},
              {"lhs_length", a->length},
              {"rhs_length", b->length},
              {"test_positives", a->counts.positives},
              {"holds", fa >= fb},
              {"verdict", undecided ? "undecided" : (fa >= fb ? "holds" : "does not hold")}};
}

std::string claimText(const json& c, const std::string& what) {
  if (c.is_null()) return "- " + what + ": not evaluated\n";
  char buf[320];
  std::snprintf(buf, sizeof buf, "- %s: **%s** (F %.2f vs %.2f; length %zu vs %zu; %zu test positives)\n",
                what.c_str(), c["verdict"].get<std::string>().c_str(), c["lhs_f_measure"].get<double>(),
                c["rhs_f_measure"].get<double>(), c["lhs_length"].get<std::size_t>(),
                c["rhs_length"].get<std::size_t>(), c["test_positives"].get<std::size_t>());
  return buf;
}

}  // namespace

const std::vector<ConfigInfo>& paperConfigs() {
  static const std::vector<ConfigInfo> c = {
      {"all", "Tab. 2: all layers (red, green, blue, intensity, hue distance, distance, remission), features a-j"},
      {"no_corners", "Tab. 3: all layers without the corner-like features (a-f only)"},
      {"laser", "Tab. 4: laser only (distance, remission)"},
      {"camera", "Tab. 5: camera only (intensity, hue distance)"},
      {"four", "Tab. 6: hue distance, intensity, distance, remission"},
      {"and", "Tab. 7: laser-only AND camera-only cascade (Tab. 4 AND Tab. 5; a detection must pass both)"},
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

json claimsJson(const ExperimentReport& r, const std::string& cls) {
  const ConfigResult* all = find(r, cls, "all");
  json j;
  j["joint_ge_laser"] = compare(all, find(r, cls, "laser"));
  j["joint_ge_camera"] = compare(all, find(r, cls, "camera"));
  j["joint_ge_and"] = compare(all, find(r, cls, "and"));
  j["four_ge_and"] = compare(find(r, cls, "four"), find(r, cls, "and"));
  j["corners_help"] = compare(all, find(r, cls, "no_corners"));
  return j;
}

std::string renderMarkdown(const ExperimentReport& r) {
  std::ostringstream md;
  md << "# " << r.title << "\n\n";
  md << "Produced by `" << r.command << "` in " << num(r.totalSeconds / 60.0, 1)
     << " min. Reproduction of the experiments of Klein, Schulz, Frintrop, \"Boosting with a Joint "
        "Feature Pool from Different Sensors\" (Tab. 2-7, Fig. 7) on this data set. "
        "`results.json` holds the same numbers.\n\n";

  md << "## Data\n\n" << r.dataDescription << "\n\n";
  md << "Stacks: " << r.trainStacks << " training, " << r.testStacks << " test.\n\n";
  {
    std::vector<std::vector<std::string>> body;
    for (const SplitCounts& c : r.counts)
      body.push_back({c.className, std::to_string(c.trainPositives), std::to_string(c.trainIgnored),
                      std::to_string(c.trainFrames), std::to_string(c.testPositives),
                      std::to_string(c.testIgnored), std::to_string(c.testFrames)});
    table(md,
          {"class", "train positives", "train ignored labels", "train frames with class", "test positives",
           "test ignored labels", "test frames with class"},
          body);
  }
  if (!r.settings.empty()) {
    md << "## Settings\n\n";
    std::vector<std::vector<std::string>> body;
    for (const auto& [k, v] : r.settings) body.push_back({k, "`" + v + "`"});
    table(md, {"setting", "value"}, body);
  }

  if (!r.failures.empty()) {
    md << "## Not evaluated\n\n";
    for (const std::string& f : r.failures) md << "- " << f << "\n";
    md << "\n";
  }
  md << "## Results in the paper's layout\n\n"
        "Length is the number of weak classifiers (stumps) in the cascade, summed over both cascades "
        "for the AND combination. Recall, precision and F-measure on the test frames: a detection "
        "hits a label with IoU >= 0.5; labels below KITTI \"moderate\" (height < 25 px or occlusion "
        "> 1) and ignore regions are neither hits nor false alarms. ms per stack: detection time on "
        "one test stack (all scales), single thread.\n\n";
  for (const ConfigInfo& info : paperConfigs()) {
    std::vector<std::string> header{""};
    std::vector<const ConfigResult*> cols;
    for (const std::string& cls : r.classes)
      if (const ConfigResult* c = find(r, cls, info.config)) {
        header.push_back(cls);
        cols.push_back(c);
      }
    if (cols.empty()) continue;
    md << "### " << info.caption << "\n\n";
    std::vector<std::vector<std::string>> body;
    for (const Row& row : rows()) {
      std::vector<std::string> line{row.name};
      for (const ConfigResult* c : cols) line.push_back(row.cell(*c));
      body.push_back(line);
    }
    if (info.config == "all") {
      std::vector<std::string> line{"corner features"};
      for (const ConfigResult* c : cols) line.push_back(num(100 * c->cornerShare, 0) + " %");
      body.push_back(line);
    }
    table(md, header, body);
  }

  // Peers: configurations that are not ours.
  std::vector<const ConfigResult*> peers;
  for (const ConfigResult& c : r.results)
    if (!c.trained) peers.push_back(&c);
  if (!peers.empty()) {
    md << "### Camera-only peers (OpenCV) on the same test frames\n\n";
    std::vector<std::string> header{""};
    for (const ConfigResult* p : peers) header.push_back(p->className + ": " + p->config);
    std::vector<std::vector<std::string>> body;
    for (const Row& row : rows()) {
      std::vector<std::string> line{row.name};
      for (const ConfigResult* p : peers) line.push_back(row.cell(*p));
      body.push_back(line);
    }
    table(md, header, body);
    for (const ConfigResult* p : peers) md << "- `" << p->config << "`: " << p->description << "\n";
    md << "\n";
  }

  md << "## Per class\n\n";
  for (const std::string& cls : r.classes) {
    std::vector<std::vector<std::string>> body;
    for (const ConfigResult& c : r.results) {
      if (c.className != cls) continue;
      body.push_back({c.config, c.trained ? std::to_string(c.length) : "-", num(c.counts.recall()),
                      num(c.counts.precision()), num(c.counts.fMeasure()), num(c.msPerStack, 1),
                      c.trained ? num(c.trainSeconds, 1) : "-", c.stopReason.empty() ? "" : c.stopReason});
    }
    if (body.empty()) continue;
    md << "### " << cls << "\n\n";
    table(md, {"configuration", "length", "recall", "precision", "F-measure", "ms per stack", "training [s]",
               "training stopped because"},
          body);
  }

  md << "## Weight share by layer (paper Fig. 7)\n\n"
        "Cascades trained on all layers, decomposed into their weak classifiers. The weight of a "
        "stump is the difference of its two leaf values, |right - left|: the amount it moves the "
        "stage sum between its two sides (a constant offset, the mean of the leaves, only shifts the "
        "stage threshold). Shares are weights summed per layer over all stages, divided by the total.\n\n";
  {
    std::map<std::string, double> allLayers;
    for (const std::string& cls : r.classes)
      if (const ConfigResult* c = find(r, cls, "all"))
        for (const auto& [l, s] : c->layerWeightShare) allLayers[l] += s;
    const std::vector<std::string> layers = orderedLayers(allLayers);
    std::vector<std::string> header{"class"};
    header.insert(header.end(), layers.begin(), layers.end());
    std::vector<std::vector<std::string>> body;
    for (const std::string& cls : r.classes) {
      const ConfigResult* c = find(r, cls, "all");
      if (!c) continue;
      std::vector<std::string> line{cls};
      for (const auto& l : layers) {
        const auto it = c->layerWeightShare.find(l);
        line.push_back(num(it == c->layerWeightShare.end() ? 0.0 : 100 * it->second, 1) + " %");
      }
      body.push_back(line);
    }
    if (!body.empty()) table(md, header, body);
    for (const std::string& cls : r.classes)
      if (find(r, cls, "all")) md << "![weight share " << cls << "](weight_share_" << cls << ".png)\n";
    md << "\n";
  }

  md << "## The paper's claims on this data\n\n"
        "Compared on the F-measure of the test frames (ties count as holding); lengths for the "
        "paper's second argument, shorter cascades. \"undecided\": fewer than 5 test positives, or F = 0 "
        "on both sides.\n\n";
  for (const std::string& cls : r.classes) {
    const json c = claimsJson(r, cls);
    md << "### " << cls << "\n\n";
    md << claimText(c["joint_ge_laser"], "joint pool (all layers) >= laser only");
    md << claimText(c["joint_ge_camera"], "joint pool (all layers) >= camera only");
    md << claimText(c["four_ge_and"], "joint pool (4 layers) >= AND of laser-only and camera-only");
    md << claimText(c["joint_ge_and"], "joint pool (all layers) >= AND of laser-only and camera-only");
    md << claimText(c["corners_help"], "corner features help (all >= all without corners)");
    md << "\n";
  }
  return md.str();
}

json toJson(const ExperimentReport& r) {
  json j;
  j["title"] = r.title;
  j["command"] = r.command;
  j["data"] = r.dataDescription;
  j["train_stacks"] = r.trainStacks;
  j["test_stacks"] = r.testStacks;
  j["total_seconds"] = r.totalSeconds;
  j["settings"] = r.settings;
  j["failures"] = r.failures;
  j["counts"] = json::array();
  for (const SplitCounts& c : r.counts)
    j["counts"].push_back({{"class", c.className},
                           {"train", {{"positives", c.trainPositives}, {"ignored_labels", c.trainIgnored}, {"frames", c.trainFrames}}},
                           {"test", {{"positives", c.testPositives}, {"ignored_labels", c.testIgnored}, {"frames", c.testFrames}}}});
  j["results"] = json::array();
  for (const ConfigResult& c : r.results) {
    json e{{"class", c.className},
           {"config", c.config},
           {"description", c.description},
           {"trained", c.trained},
           {"layers", c.layers},
           {"recall", c.counts.recall()},
           {"precision", c.counts.precision()},
           {"f_measure", c.counts.fMeasure()},
           {"hits", c.counts.hits},
           {"false_alarms", c.counts.falseAlarms},
           {"misses", c.counts.misses},
           {"positives", c.counts.positives},
           {"ignored_detections", c.counts.ignored},
           {"stacks", c.counts.stacks},
           {"ms_per_stack", c.msPerStack}};
    if (c.trained) {
      e["length"] = c.length;
      e["stages"] = c.stages;
      e["pool_size"] = c.poolSize;
      e["train_seconds"] = c.trainSeconds;
      e["layer_weight_share"] = c.layerWeightShare;
      e["corner_share"] = c.cornerShare;
      e["stop_reason"] = c.stopReason;
    }
    j["results"].push_back(std::move(e));
  }
  j["claims"] = json::object();
  for (const std::string& cls : r.classes) j["claims"][cls] = claimsJson(r, cls);
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

cv::Mat detectionMosaic(const std::vector<MosaicTile>& tiles, int tileWidth, int columns) {
  if (tiles.empty() || columns < 1 || tileWidth < 16) return {};
  std::vector<cv::Mat> drawn;
  int tileH = 0;
  for (const MosaicTile& t : tiles) {
    const double s = static_cast<double>(tileWidth) / t.bgr.cols;
    cv::Mat img;
    cv::resize(t.bgr, img, {}, s, s, cv::INTER_AREA);
    const auto rect = [s](const Box& b) {
      return cv::Rect(static_cast<int>(std::lround(b.x * s)), static_cast<int>(std::lround(b.y * s)),
                      static_cast<int>(std::lround(b.w * s)), static_cast<int>(std::lround(b.h * s)));
    };
    for (std::size_t i = 0; i < t.labels.size(); ++i) {
      const auto role = i < t.match.labelRoles.size() ? t.match.labelRoles[i] : boosting::LabelRole::kBackground;
      if (role == boosting::LabelRole::kPositive)
        cv::rectangle(img, rect(t.labels[i].box), cv::Scalar(255, 80, 0), 1);
      else if (role != boosting::LabelRole::kBackground)
        cv::rectangle(img, rect(t.labels[i].box), cv::Scalar(150, 150, 150), 1);
    }
    for (std::size_t i = 0; i < t.detections.size(); ++i) {
      const auto o = i < t.match.detections.size() ? t.match.detections[i] : boosting::DetectionOutcome::kIgnored;
      const cv::Scalar c = o == boosting::DetectionOutcome::kHit          ? cv::Scalar(0, 200, 0)
                           : o == boosting::DetectionOutcome::kFalseAlarm ? cv::Scalar(0, 0, 255)
                                                                          : cv::Scalar(0, 220, 220);
      cv::rectangle(img, rect(t.detections[i].box), c, 2);
    }
    cv::rectangle(img, cv::Rect(0, 0, img.cols, 18), cv::Scalar(0, 0, 0), cv::FILLED);
    cv::putText(img, t.caption, {4, 13}, cv::FONT_HERSHEY_SIMPLEX, 0.42, cv::Scalar(255, 255, 255), 1, cv::LINE_AA);
    tileH = std::max(tileH, img.rows);
    drawn.push_back(img);
  }
  const int rowsN = (static_cast<int>(drawn.size()) + columns - 1) / columns;
  const int colsN = std::min(columns, static_cast<int>(drawn.size()));
  cv::Mat mosaic(rowsN * (tileH + 4), colsN * (tileWidth + 4), CV_8UC3, cv::Scalar(40, 40, 40));
  for (std::size_t i = 0; i < drawn.size(); ++i) {
    const int r = static_cast<int>(i) / columns, c = static_cast<int>(i) % columns;
    drawn[i].copyTo(mosaic(cv::Rect(c * (tileWidth + 4), r * (tileH + 4), drawn[i].cols, drawn[i].rows)));
  }
  return mosaic;
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
