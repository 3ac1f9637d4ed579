#pragma once
// `fusedet experiments`, output side: report.md (tables shaped like the paper's Tab. 2-7 plus a
// per-class comparison and the paper's claims checked on the measured numbers), results.json,
// the weight-share-by-layer bar chart per class (paper Fig. 7) and the detection mosaics.

#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/label.h"

namespace fusedet::tools::experiments {

// One configuration (trained pool subset, AND combination or peer) evaluated for one class.
struct ConfigResult {
  std::string className;
  std::string config;       // "all", "no_corners", "laser", "camera", "four", "and", "hog", ...
  std::string description;  // what it is, for the report
  bool trained = true;      // false for peers (no length, training time, weight shares)
  std::vector<std::string> layers;
  std::size_t poolSize = 0;  // candidate features (0 for peers and AND)
  std::size_t length = 0;    // weak classifiers (AND: both cascades together)
  std::size_t stages = 0;
  boosting::Counts counts;
  double msPerStack = 0;
  double trainSeconds = 0;
  std::map<std::string, double> layerWeightShare;  // layer -> share of the summed weight, sums to 1
  double cornerShare = 0;                          // share of weak classifiers that are corners
  std::string stopReason;                          // why training stopped, as the trainer said it
};

// Counts of one class in one split.
struct SplitCounts {
  std::string className;
  std::size_t trainPositives = 0, trainIgnored = 0, trainFrames = 0;
  std::size_t testPositives = 0, testIgnored = 0, testFrames = 0;
};

struct ExperimentReport {
  std::string title = "fusedet experiments";
  std::string command;                    // the command line that produced it
  std::string dataDescription;            // data set and split, one paragraph
  std::size_t trainStacks = 0, testStacks = 0;
  std::vector<std::string> classes;       // table columns, in order
  std::vector<SplitCounts> counts;
  std::vector<ConfigResult> results;
  std::map<std::string, std::string> settings;  // shown in a table and in results.json
  std::vector<std::string> failures;            // configurations that could not be trained, and why
  double totalSeconds = 0;
};

// Configurations in the order of the paper's tables, with their table captions.
struct ConfigInfo {
  std::string config, caption;
};
const std::vector<ConfigInfo>& paperConfigs();

// Layer order for charts and tables: the paper's Fig. 3 order, unknown layers after it.
std::vector<std::string> orderedLayers(const std::map<std::string, double>& shares);

std::string renderMarkdown(const ExperimentReport& report);
nlohmann::json toJson(const ExperimentReport& report);
// The paper's claims on the measured numbers of one class (missing configs: not evaluated).
nlohmann::json claimsJson(const ExperimentReport& report, const std::string& className);

// Bar chart of weight share per layer (paper Fig. 7), one bar per layer, as an 8-bit BGR image.
cv::Mat weightShareChart(const std::string& title, const std::map<std::string, double>& shares);

// One tile of a detection mosaic: the image with labels and classified detections drawn.
struct MosaicTile {
  cv::Mat bgr;
  Labels labels;
  std::vector<Detection> detections;
  boosting::StackMatch match;  // outcomes of `detections` and roles of `labels`
  std::string caption;
};
// Tiles scaled to `tileWidth`, `columns` per row. Colours: green hit, red false alarm, yellow
// ignored detection, blue positive label, grey ignored label or region.
cv::Mat detectionMosaic(const std::vector<MosaicTile>& tiles, int tileWidth = 620, int columns = 2);

// Writes report.md and results.json into `dir` (created if needed).
void writeReport(const std::filesystem::path& dir, const ExperimentReport& report);

}  // namespace fusedet::tools::experiments
