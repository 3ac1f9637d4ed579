// SPDX-License-Identifier: Apache-2.0
#pragma once
// The options of `fusedet experiments`: what they hold, their command-line definition, and the
// training, detection and plan they give (the preset with the options applied).

#include <CLI/CLI.hpp>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "../data_dir.h"
#include "../network_options.h"
#include "../training_options.h"
#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/experiments/experiment_plan.h"

namespace fusedet::tools::experiments {
namespace fs = std::filesystem;

struct ExperimentOptions {
  fs::path data = defaultDataDir();
  fs::path out;
  fs::path datasetCache;  // default OUT/dataset
  fs::path modelCache;    // default OUT/fold-models
  fs::path modelsOut;     // optional: the all-layers model per class trained on every frame
  fs::path trainLabels;   // optional: a data set of the same items whose labels the cascades train on
  std::string trainLabelsKey;  // its labelsKey() once read by runExperiments (chainFor() passes it on)
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
  TrainingOptions training;  // ../training_options.h, as fusedet train's; not given = the preset's
  double scaleFactor = 0;
  double step = 0;
  int minNeighbors = 3;
  bool laserExtent = false;  // boosting::LaserExtentParams on the test frames' detections
  // Per-class detection settings (fusedet/boost/class_detection.h, car) where the preset uses them; an
  // option given on the command line applies to every class instead.
  bool classDetection = true;
  bool minNeighborsGiven = false, laserExtentGiven = false;
  std::size_t minPositives = 4;
  std::vector<std::string> classStagesText;       // --class-stages as given, parsed by runExperiments
  std::map<std::string, std::size_t> classStages;  // class -> stages its cascades keep (0/absent = all)
  std::vector<std::size_t> stageSweep;             // stage counts the `all` fold cascades are cut to
  std::vector<int> neighborsSweep;                 // min neighbours of that sweep (default: --min-neighbors)
  bool missAnalysis = true;                        // explain every missed positive of `all`
  NetworkOptions network;                          // the network of the all_neural and neural configurations
  std::string commandLine;
};

// Layers and feature types of each trained configuration (paper §4).
struct TrainedConfig {
  std::string name;
  std::vector<std::string> layers;
  std::string types;  // feature letters
};

const std::vector<TrainedConfig>& trainedConfigs();

const TrainedConfig& trainedConfig(const std::string& name);

// Whether any configuration of the plan trains on the network's score layers.
bool needsNetwork(const std::vector<std::string>& configs);

// "1,2,all" / "none" -> {1, 2, 0}: the counts of a learning curve (0 = all).
std::vector<std::size_t> parseLearningCounts(const std::vector<std::string>& values, const std::string& option);

// The preset (fusedet/experiments/experiment_plan.h) with the options given on the command line.
boosting::ExperimentPlan planFor(const ExperimentOptions& o);

// Grouping of the raw hits, as the options give it (fusedetd's detection.* keys mean the same).
boosting::GroupParams groupParams(const ExperimentOptions& o);

std::string groupingText(const ExperimentOptions& o);

boosting::TrainingConfig trainingConfig(const ExperimentOptions& o, const boosting::ExperimentPlan& p, const std::string& cls,
                                        const TrainedConfig& tc, const boosting::MatchConfig& match);

// Stages a class's cascades keep (--class-stages); 0 = every trained stage.
std::size_t keptStages(const ExperimentOptions& o, const std::string& cls);

// "person=5,bike=4" -> {person: 5, bike: 4}.
std::map<std::string, std::size_t> parseClassStages(const std::vector<std::string>& items);

boosting::ChainSpec chainFor(const ExperimentOptions& o, const boosting::ExperimentPlan& p, const std::string& cls,
                             const std::string& config, const boosting::MatchConfig& match);

// Every option of `fusedet experiments`, parsed into *o.
void addExperimentOptions(CLI::App& app, const std::shared_ptr<ExperimentOptions>& o);

}  // namespace fusedet::tools::experiments
