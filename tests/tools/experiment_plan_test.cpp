// SPDX-License-Identifier: Apache-2.0
// The presets of `fusedet experiments` (experiment_plan.h): "bundled" must train the way the bundled
// models were trained - checked against what models/*.json record about their own training, not
// against numbers copied into this test - and the plan's rules (which configurations run for which
// class, unknown names) hold.

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <stdexcept>
#include <string>

#include "fusedet/experiments/experiment_plan.h"
#include "fusedet/boost/gentle_boost.h"

namespace fusedet::boosting {
namespace {

nlohmann::json bundledModel(const std::string& cls) {
  std::ifstream in(std::string(FUSEDET_SOURCE_DIR) + "/models/" + cls + ".json");
  EXPECT_TRUE(in) << cls;
  return nlohmann::json::parse(in);
}

TEST(ExperimentPlan, BundledTrainsLikeTheBundledModels) {
  const ExperimentPlan p = experimentPlan("bundled");
  const StageConfig stageDefaults;
  for (const std::string cls : {"car", "person", "bike"}) {
    const nlohmann::json m = bundledModel(cls);
    const nlohmann::json& t = m.at("training");
    EXPECT_EQ(std::stoi(t.at("grid").get<std::string>()), p.grid) << cls;
    EXPECT_DOUBLE_EQ(std::stod(t.at("min_hit").get<std::string>()), stageDefaults.minHit) << cls;
    EXPECT_DOUBLE_EQ(std::stod(t.at("max_fa").get<std::string>()), stageDefaults.maxFalseAlarm) << cls;
    EXPECT_EQ(t.at("types").get<std::string>(), "all") << cls;
    // The stop reason names the target rate the model was trained for ("target 1e-05" or "<= 1e-05").
    const std::string stop = t.at("stop_reason").get<std::string>();
    const double target = std::stod(stop.substr(stop.find_last_of(" ") + 1));
    EXPECT_DOUBLE_EQ(target, p.targetFalseAlarm) << stop;
    EXPECT_LE(m.at("stages").size(), static_cast<std::size_t>(p.maxStages)) << cls;
    for (const auto& stage : m.at("stages")) EXPECT_LE(stage.at("stumps").size(), static_cast<std::size_t>(p.maxWeak));
    if (stop.rfind("stage limit", 0) == 0) {
      EXPECT_EQ(m.at("stages").size(), static_cast<std::size_t>(p.maxStages)) << stop;
    }
  }
  EXPECT_EQ(p.negatives, 0u);  // the trainer's rule, as `fusedet train` used for the models
}

TEST(ExperimentPlan, BundledIsTheDocsResultsPlan) {
  const ExperimentPlan p = experimentPlan("bundled");
  EXPECT_EQ(experimentPlanNames().front(), "bundled");  // the default comes first
  EXPECT_EQ(p.folds, 0);                                // leave-one-drive-out
  EXPECT_EQ(p.configs.front(), "all");
  for (const std::string c : {"no_corners", "laser", "camera", "and"})
    EXPECT_NE(std::find(p.configs.begin(), p.configs.end(), c), p.configs.end()) << c;
  EXPECT_TRUE(runsFor(p, "all", "person"));
  EXPECT_TRUE(runsFor(p, "laser", "car"));
  EXPECT_FALSE(runsFor(p, "laser", "person"));
  EXPECT_FALSE(p.learningDrives.empty());
  EXPECT_EQ(p.learningDrives.back(), 0u);  // ends at every training drive
  // The curve over training positives: from 8 (fewer than person's 6-14 per fold) up, doubling.
  ASSERT_GE(p.learningPositives.size(), 3u);
  EXPECT_EQ(p.learningPositives.front(), 8u);
  EXPECT_EQ(p.learningPositives.back(), 0u);
  EXPECT_TRUE(p.trainingScore);
  EXPECT_GE(p.resamples, 1000u);
}

TEST(ExperimentPlan, QuickIsSmallerInEveryCostlyPart) {
  const ExperimentPlan b = experimentPlan("bundled"), q = experimentPlan("quick");
  EXPECT_LT(q.grid, b.grid);
  EXPECT_LT(q.maxStages, b.maxStages);
  EXPECT_LT(q.maxWeak, b.maxWeak);
  EXPECT_GT(q.targetFalseAlarm, b.targetFalseAlarm);
  EXPECT_GT(q.trainStep, b.trainStep);
  EXPECT_GT(q.folds, 0);  // drive-disjoint folds, not one per drive
  EXPECT_LT(q.learningDrives.size(), b.learningDrives.size());
  EXPECT_LT(q.learningPositives.size(), b.learningPositives.size());
  EXPECT_FALSE(q.learningPositives.empty());  // the quick test runs that curve too
}

TEST(ExperimentPlan, EmptyConfigClassesMeansEveryClass) {
  ExperimentPlan p = experimentPlan("quick");
  p.configClasses.clear();
  EXPECT_TRUE(runsFor(p, "and", "bike"));
  p.configClasses = {"bike"};
  EXPECT_TRUE(runsFor(p, "and", "bike"));
  EXPECT_FALSE(runsFor(p, "and", "car"));
  EXPECT_TRUE(runsFor(p, "all", "car"));
}

TEST(ExperimentPlan, UnknownPresetIsNamedWithTheKnownOnes) {
  try {
    experimentPlan("full");
    FAIL() << "no exception";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("'full'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("bundled, quick"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fusedet::boosting
