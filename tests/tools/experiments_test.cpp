// SPDX-License-Identifier: Apache-2.0
// `fusedet experiments` helpers: the split, the class rules and counts (checked against the counts
// the data set's SOURCE.md states), the peers on a real frame, and the report writers.

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <iterator>
#include <nlohmann/json.hpp>
#include <set>
#include <opencv2/core.hpp>

#include "../../tools/experiments/peers.h"
#include "../../tools/experiments/report.h"
#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::tools::experiments {
namespace {
namespace fs = std::filesystem;
using namespace boosting;

std::vector<DatasetEntry> entries(const std::string& group, int n) {
  std::vector<DatasetEntry> e;
  for (int i = 0; i < n; ++i) e.push_back({group + "/" + std::to_string(i), group});
  return e;
}

TEST(ExperimentsSplit, FirstTwoThirdsOfEachGroupTrain) {
  auto all = entries("kitti", 52);
  const auto b = entries("kitti_0009", 26);
  const auto c = entries("object", 3);
  all.insert(all.end(), b.begin(), b.end());
  all.insert(all.end(), c.begin(), c.end());
  const Split s = splitByFrame(all);
  // round(52 * 2/3) = 35, round(26 * 2/3) = 17, round(3 * 2/3) = 2.
  EXPECT_EQ(s.train.size(), 35u + 17u + 2u);
  EXPECT_EQ(s.test.size(), 17u + 9u + 1u);
  EXPECT_EQ(s.train[34].id, "kitti/34");
  EXPECT_EQ(s.test[0].id, "kitti/35");
  EXPECT_EQ(s.test[17].id, "kitti_0009/17");
  EXPECT_EQ(s.test.back().id, "object/2");
  EXPECT_THROW(splitByFrame(all, 1.5), std::invalid_argument);
}

TEST(ExperimentsSplit, InterleavedGroupsKeepTheirOrder) {
  const std::vector<DatasetEntry> e{{"a/0", "a"}, {"b/0", "b"}, {"a/1", "a"}, {"b/1", "b"}, {"a/2", "a"}};
  const Split s = splitByFrame(e);
  ASSERT_EQ(s.train.size(), 3u);  // a: round(2) = 2, b: round(1.33) = 1
  EXPECT_EQ(s.train[0].id, "a/0");
  EXPECT_EQ(s.train[1].id, "a/1");
  EXPECT_EQ(s.train[2].id, "b/0");
  EXPECT_EQ(s.test[0].id, "a/2");
}

TEST(ExperimentsRules, VanPolicyAndTrainingLabels) {
  EXPECT_EQ(parseVanPolicy("ignore"), VanPolicy::kIgnore);
  EXPECT_THROW(parseVanPolicy("maybe"), std::invalid_argument);
  Labels labels(4);
  labels[0].className = "car";  labels[0].box = {0, 0, 50, 40};
  labels[1].className = "car";  labels[1].box = {0, 0, 20, 10};   // below 25 px
  labels[2].className = "van";  labels[2].box = {0, 0, 60, 50};
  labels[3].className = "DontCare"; labels[3].ignore = true;
  const Labels neg = trainingLabels(labels, matchConfigFor("car", VanPolicy::kNegative));
  ASSERT_EQ(neg.size(), 3u);  // the van is gone: negative material
  EXPECT_FALSE(neg[0].ignore);
  EXPECT_TRUE(neg[1].ignore);
  EXPECT_TRUE(neg[2].ignore);
  const Labels pos = trainingLabels(labels, matchConfigFor("car", VanPolicy::kPositive));
  ASSERT_EQ(pos.size(), 4u);
  EXPECT_EQ(pos[2].className, "car");
  EXPECT_FALSE(pos[2].ignore);
  const Labels ign = trainingLabels(labels, matchConfigFor("car", VanPolicy::kIgnore));
  EXPECT_TRUE(ign[2].ignore);
  // For person, cars and vans are background: removed.
  EXPECT_EQ(trainingLabels(labels, matchConfigFor("person", VanPolicy::kNegative)).size(), 1u);
}

fs::path kittiDir() { return fs::path(FUSEDET_DATA_DIR) / "kitti"; }

TEST(ExperimentsRules, CountsMatchTheDataSetsSourceNotes) {
  if (!fs::is_directory(kittiDir())) GTEST_SKIP() << "no KITTI data at " << kittiDir();
  std::vector<Labels> frames;
  for (const auto& id : fusion::listKittiFrames(kittiDir()))
    frames.push_back(fusion::readKittiLabels(kittiDir() / "label_2" / (id + ".txt")));
  // SOURCE.md: "Car 82, Van 99, Cyclist 52, Pedestrian 8"; frames: Car 15, Cyclist 52, Pedestrian 8.
  boosting::MatchConfig every = matchConfigFor("car", VanPolicy::kNegative);
  every.minHeight = 0;
  every.maxOcclusion = 3;
  every.maxTruncation = -1;
  InstanceCount car = countInstances(frames, every);
  EXPECT_EQ(car.positives, 82u);
  EXPECT_EQ(car.frames, 15u);
  every.className = "bike";
  EXPECT_EQ(countInstances(frames, every).positives, 52u);
  every.className = "person";
  const InstanceCount person = countInstances(frames, every);
  EXPECT_EQ(person.positives, 8u);
  EXPECT_EQ(person.frames, 8u);
  every.className = "car";
  every.aliasClasses = {"van"};
  EXPECT_EQ(countInstances(frames, every).positives, 82u + 99u);
  // Moderate rules only drop labels, they never add any.
  const InstanceCount moderate = countInstances(frames, matchConfigFor("car", VanPolicy::kNegative));
  EXPECT_EQ(moderate.positives + moderate.ignoredLabels, 82u);
}

TEST(ExperimentsPeers, RunOnARealFrame) {
  if (!fs::is_directory(kittiDir())) GTEST_SKIP() << "no KITTI data at " << kittiDir();
  const fusion::KittiFrame f = fusion::readKittiFrame(kittiDir(), "000000");
  LayerStack stack(f.image.cols, f.image.rows);
  std::vector<cv::Mat> bgr;
  cv::split(f.image, bgr);
  stack.set({"red", bgr[2], {}});
  stack.set({"green", bgr[1], {}});
  stack.set({"blue", bgr[0], {}});
  const cv::Mat back = stackToBgr(stack);
  EXPECT_EQ(cv::norm(back, f.image, cv::NORM_INF), 0.0);
  for (const auto& peer : {makeHogPeer(1.0), makeHaarFullbodyPeer(defaultHaarFullbodyPath(), 1.0)}) {
    for (const Detection& d : peer->detect(back)) {
      EXPECT_EQ(d.className, "person");
      EXPECT_GE(d.box.x, -1);
      EXPECT_LE(d.box.right(), f.image.cols + 1) << peer->name();
      EXPECT_GT(d.box.h, d.box.w) << peer->name() << ": people detectors find upright boxes";
    }
  }
  EXPECT_THROW(makeHaarFullbodyPeer("/nonexistent/cascade.xml"), std::runtime_error);
}

TEST(ExperimentsReport, TablesJsonAndClaimsFollowTheNumbers) {
  ExperimentReport r;
  r.command = "fusedet experiments --quick";
  r.classes = {"car"};
  ConfigResult c;
  c.className = "car";
  c.config = "all";
  c.counts.positives = 10;
  c.counts.hits = 9;
  c.counts.misses = 1;
  c.counts.falseAlarms = 1;
  c.f.value = 0.9;
  c.f.interval = boosting::Interval{0.8, 0.97, 200};
  c.layerWeightShare = {{"distance", 0.75}, {"intensity", 0.25}};
  r.results.push_back(c);
  ConfigResult none = c;  // a configuration that detected nothing: precision undefined
  none.config = "camera";
  none.counts.hits = 0;
  none.counts.falseAlarms = 0;
  none.counts.misses = 10;
  none.f = {0.0, boosting::Interval{0, 0, 200}};
  r.results.push_back(none);
  Claim claim;
  claim.className = "car";
  claim.key = "joint_gt_camera";
  claim.text = "joint pool (all layers) > camera only";
  claim.fDifference = {0.9, boosting::Interval{0.8, 0.97, 200}};
  claim.verdict = boosting::verdict(claim.fDifference.interval);
  r.claims.push_back(claim);
  r.goals.push_back({"car", "F >= 0.8", 0.8, c.f});
  const nlohmann::json j = toJson(r);
  EXPECT_NEAR(j["results"][0]["f_measure"]["value"].get<double>(), 0.9, 1e-12);
  EXPECT_NEAR(j["results"][0]["f_measure"]["ci95"][0].get<double>(), 0.8, 1e-12);
  EXPECT_TRUE(j["results"][1]["precision"].is_null());
  EXPECT_EQ(j["claims"][0]["verdict"], "holds");
  EXPECT_TRUE(j["goals"][0]["met"].get<bool>());
  const std::string md = renderMarkdown(r);
  EXPECT_NE(md.find("| all | 0.90 [0.80, 0.97] | null |"), std::string::npos) << md;
  EXPECT_NE(md.find("| camera | 0.00 [0.00, 0.00] | null | 0.00 | null |"), std::string::npos) << md;
  EXPECT_NE(md.find("**holds**"), std::string::npos);
  // Fig. 7 chart and the line charts are drawn.
  EXPECT_FALSE(weightShareChart("car", c.layerWeightShare).empty());
  EXPECT_EQ(orderedLayers(c.layerWeightShare), (std::vector<std::string>{"intensity", "distance"}));
  const cv::Mat chart = lineChart("pr", "recall", "precision", 1.0, {{"all", {{0.1, 1.0}, {0.5, 0.6}}, {}}});
  EXPECT_EQ(chart.type(), CV_8UC3);
  EXPECT_GT(chart.cols, 500);
}

// Learning-curve points: per-fold counts and the training score reach the table and results.json;
// the chart holds one panel per axis measured.
TEST(ExperimentsReport, LearningPointsShowTrainingScoreAndWhatEachFoldTrainedOn) {
  ExperimentReport r;
  r.classes = {"car"};
  LearningPoint p;
  p.className = "car";
  p.axis = "positives";
  p.requested = 8;
  p.perFold = {{3, 10, 1, 4}, {12, 9, 2, 9}};  // frames, positives, drives, distinct objects
  p.counts.hits = 5;
  p.counts.falseAlarms = 7;
  p.counts.misses = 20;
  p.f = {0.17, boosting::Interval{0.13, 0.21, 200}};
  p.trainingScored = true;
  p.trainingCounts.hits = 9;
  p.trainingF = {0.49, boosting::Interval{0.27, 0.66, 200}};
  r.learning.push_back(p);
  EXPECT_DOUBLE_EQ(p.meanPositives(), 9.5);
  const std::string md = renderMarkdown(r);
  EXPECT_NE(md.find("### Over training positives"), std::string::npos) << md;
  EXPECT_EQ(md.find("### Over training drives"), std::string::npos) << md;
  EXPECT_NE(md.find("| car | 8 | 10 / 9 | 4 / 9 | 1 / 2 | 3 / 12 | 0.17 [0.13, 0.21] |"), std::string::npos) << md;
  EXPECT_NE(md.find("| 5 / 7 / 20 | 0.49 [0.27, 0.66] |"), std::string::npos) << md;
  const nlohmann::json j = toJson(r);
  EXPECT_EQ(j["learning_curve"][0]["positives_asked"], 8);
  EXPECT_EQ(j["learning_curve"][0]["folds"][1]["distinct_objects"], 9);
  EXPECT_NEAR(j["learning_curve"][0]["training"]["f_measure"]["value"].get<double>(), 0.49, 1e-12);
  const cv::Mat one = learningChart("car", r.learning);
  LearningPoint d = p;
  d.axis = "drives";
  d.drives = 2;
  r.learning.push_back(d);
  const cv::Mat two = learningChart("car", r.learning);
  EXPECT_EQ(two.cols, 2 * one.cols);
  EXPECT_TRUE(learningChart("bike", r.learning).empty());
}

}  // namespace
}  // namespace fusedet::tools::experiments

namespace fusedet::tools::experiments {
namespace {
using namespace boosting;

// A one-stump cascade on one layer: accepts windows whose left half is brighter than the right.
boosting::Cascade edgeCascade(const std::string& layerName, double threshold) {
  boosting::Cascade c;
  c.className = "car";
  c.windowWidth = 24;
  c.windowHeight = 24;
  c.layers = {layerName};
  const int f = c.addFeature({boosting::FeatureType::kEdgeHorizontal, {0, 0, 1, 1}, 0});
  boosting::Stage s;
  s.stumps = {boosting::Stump{f, threshold, -1, 1}};
  s.threshold = 0;
  c.stages = {s};
  return c;
}

TEST(ExperimentsRun, AndChainKeepsExactlyTheWindowsBothCascadesAccept) {
  cv::Mat a(96, 160, CV_32F), b(96, 160, CV_32F);
  cv::RNG rng(7);
  rng.fill(a, cv::RNG::UNIFORM, 0, 1);
  rng.fill(b, cv::RNG::UNIFORM, 0, 1);
  LayerStack stack(160, 96);
  stack.set({"intensity", a, {}});
  stack.set({"distance", b, {}});
  const boosting::Detector camera(edgeCascade("intensity", 0.01));
  const boosting::Detector laser(edgeCascade("distance", 0.01));
  DetectionSetup setup;
  setup.scan.scaleFactor = 1.25;
  setup.scan.threads = 1;
  setup.group.minNeighbors = 0;  // every accepted window becomes a detection: compare windows
  const auto boxes = [](const std::vector<Detection>& d) {
    std::set<std::array<double, 4>> s;
    for (const Detection& x : d) s.insert({x.box.x, x.box.y, x.box.w, x.box.h});
    return s;
  };
  const auto onlyLaser = boxes(detectChain({&laser}, stack, setup));
  const auto onlyCamera = boxes(detectChain({&camera}, stack, setup));
  const auto both = boxes(detectChain({&laser, &camera}, stack, setup));
  std::set<std::array<double, 4>> expected;
  std::set_intersection(onlyLaser.begin(), onlyLaser.end(), onlyCamera.begin(), onlyCamera.end(),
                        std::inserter(expected, expected.begin()));
  ASSERT_GT(onlyLaser.size(), 10u);  // random layers: roughly half the windows pass each
  ASSERT_GT(onlyCamera.size(), 10u);
  EXPECT_LT(expected.size(), onlyLaser.size());
  EXPECT_EQ(both, expected);
  // The order of the chain does not change which windows survive.
  EXPECT_EQ(boxes(detectChain({&camera, &laser}, stack, setup)), expected);
  EXPECT_THROW(detectChain({}, stack, setup), std::invalid_argument);
}

TEST(ExperimentsRun, EvaluateChainCountsOverItems) {
  cv::Mat a(96, 160, CV_32F, cv::Scalar(0));
  a(cv::Rect(40, 30, 12, 24)).setTo(1);  // a bright left half of a 24x24 window at (40, 30)
  DatasetItem item;
  item.id = "x/0";
  item.stack = LayerStack(160, 96);
  item.stack.set({"intensity", a, {}});
  Label l;
  l.className = "car";
  l.box = {40, 30, 24, 24};
  item.labels = {l};
  const boosting::Detector det(edgeCascade("intensity", 0.5));
  DetectionSetup setup;
  setup.scan.threads = 1;
  setup.scan.step = 1;
  setup.scan.maxWidth = 24;  // base size only
  setup.scan.maxHeight = 24;
  setup.group.minNeighbors = 0;
  boosting::MatchConfig match = matchConfigFor("car", VanPolicy::kNegative);
  match.minHeight = 20;  // the 24 px test label would be below KITTI moderate
  match.minDetectionHeight = 20;
  const EvalOutcome r = evaluateChain({&det}, {item, item}, match, setup);
  EXPECT_EQ(r.counts.stacks, 2u);
  EXPECT_EQ(r.counts.positives, 2u);
  EXPECT_EQ(r.counts.hits, 2u);  // the window exactly on the label is accepted in both stacks
  EXPECT_EQ(r.detections.size(), 2u);
  // Neighbouring windows that also pass are false alarms (no grouping here).
  EXPECT_EQ(r.counts.falseAlarms, 2 * (r.detections[0].size() - 1));
  EXPECT_GT(r.msPerStack, 0.0);
}

}  // namespace
}  // namespace fusedet::tools::experiments
