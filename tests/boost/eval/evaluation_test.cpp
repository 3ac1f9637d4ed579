// SPDX-License-Identifier: Apache-2.0
// Matching detections to labels: hand-checked boxes whose IoU / coverage is worked out in the
// comments, and the F-measure checked against the paper's own table values.

#include <gtest/gtest.h>

#include "fusedet/boost/evaluation.h"

namespace fusedet::boosting {
namespace {

Label label(std::string cls, Box box, int occlusion = 0, bool ignore = false) {
  Label l;
  l.className = cls;
  l.sourceClass = cls;
  l.box = box;
  l.occlusion = occlusion;
  l.ignore = ignore;
  return l;
}

Detection det(Box box, double score = 1, std::string cls = "car") {
  Detection d;
  d.className = std::move(cls);
  d.box = box;
  d.score = score;
  return d;
}

MatchConfig carConfig() {
  MatchConfig c;
  c.className = "car";
  return c;
}

TEST(Evaluation, ExactBoxIsAHit) {
  const Labels labels{label("car", {100, 100, 100, 50})};
  const StackMatch m = matchDetections({det({100, 100, 100, 50})}, labels, carConfig());
  EXPECT_EQ(m.hits, 1u);
  EXPECT_EQ(m.falseAlarms, 0u);
  EXPECT_EQ(m.misses, 0u);
  EXPECT_EQ(m.hitBy[0], 0);
}

TEST(Evaluation, IouThresholdIsInclusive) {
  const Labels labels{label("car", {0, 0, 100, 100})};
  // 100x50 inside 100x100: IoU = 5000 / 10000 = 0.5 exactly -> hit.
  EXPECT_EQ(matchDetections({det({0, 0, 100, 50})}, labels, carConfig()).hits, 1u);
  // 100x49: IoU = 0.49 -> false alarm, and the car is missed.
  const StackMatch m = matchDetections({det({0, 0, 100, 49})}, labels, carConfig());
  EXPECT_EQ(m.hits, 0u);
  EXPECT_EQ(m.falseAlarms, 1u);
  EXPECT_EQ(m.misses, 1u);
  // A stricter threshold is honoured: 100x60 has IoU 0.6 < 0.7.
  MatchConfig strict = carConfig();
  strict.minIou = 0.7;
  EXPECT_EQ(matchDetections({det({0, 0, 100, 60})}, labels, strict).falseAlarms, 1u);
}

TEST(Evaluation, LabelsBelowModerateAreNeitherHitNorFalseAlarm) {
  const Labels labels{label("car", {0, 0, 40, 24}),            // 24 px high < 25
                      label("car", {200, 0, 60, 40}, 2),       // occlusion 2 > 1
                      label("car", {400, 0, 60, 25})};         // exactly 25 px: positive
  const StackMatch m = matchDetections(
      {det({0, 0, 40, 24}), det({200, 0, 60, 40}), det({400, 0, 60, 25})}, labels, carConfig());
  EXPECT_EQ(m.labelRoles[0], LabelRole::kIgnoredLabel);
  EXPECT_EQ(m.labelRoles[1], LabelRole::kIgnoredLabel);
  EXPECT_EQ(m.labelRoles[2], LabelRole::kPositive);
  EXPECT_EQ(m.positives, 1u);
  EXPECT_EQ(m.hits, 1u);
  EXPECT_EQ(m.ignored, 2u);
  EXPECT_EQ(m.falseAlarms, 0u);
  // Missing an ignored label is not a miss.
  EXPECT_EQ(matchDetections({}, labels, carConfig()).misses, 1u);
  // Limits are configurable: with minHeight 20 and maxOcclusion 2 all three count.
  MatchConfig loose = carConfig();
  loose.minHeight = 20;
  loose.maxOcclusion = 2;
  EXPECT_EQ(matchDetections({}, labels, loose).positives, 3u);
}

TEST(Evaluation, TruncationLimitIsModerateByDefault) {
  Label l = label("car", {0, 0, 50, 50});
  l.truncation = 0.4;  // object-benchmark fraction above 0.3
  EXPECT_EQ(labelRole(l, carConfig()), LabelRole::kIgnoredLabel);
  l.truncation = 0.3;  // exactly the limit
  EXPECT_EQ(labelRole(l, carConfig()), LabelRole::kPositive);
  l.truncation = 1;  // tracking level 1 (partly truncated): fails the same numeric test
  EXPECT_EQ(labelRole(l, carConfig()), LabelRole::kIgnoredLabel);
  l.truncation = 0;  // tracking level 0
  EXPECT_EQ(labelRole(l, carConfig()), LabelRole::kPositive);
  MatchConfig c = carConfig();
  c.maxTruncation = -1;  // not checked
  l.truncation = 2;
  EXPECT_EQ(labelRole(l, c), LabelRole::kPositive);
}

TEST(Evaluation, IgnoreRegionAbsorbsDetectionsMostlyInsideIt) {
  const Labels labels{label("DontCare", {0, 0, 100, 100}, 0, true)};
  // Fully inside: coverage 1.
  const StackMatch in = matchDetections({det({10, 10, 50, 50})}, labels, carConfig());
  EXPECT_EQ(in.ignored, 1u);
  EXPECT_EQ(in.falseAlarms, 0u);
  // 50x50 at x=60: 40 of 50 columns inside -> coverage 0.8 -> ignored.
  EXPECT_EQ(matchDetections({det({60, 0, 50, 50})}, labels, carConfig()).ignored, 1u);
  // At x=80: 20/50 = 0.4 inside -> false alarm.
  EXPECT_EQ(matchDetections({det({80, 0, 50, 50})}, labels, carConfig()).falseAlarms, 1u);
  // Several detections may fall into one region.
  EXPECT_EQ(matchDetections({det({0, 0, 30, 30}), det({40, 40, 30, 30})}, labels, carConfig()).ignored, 2u);
}

TEST(Evaluation, VanIsAHardNegativeUnlessConfigured) {
  const Labels labels{label("van", {0, 0, 80, 60})};
  const std::vector<Detection> d{det({0, 0, 80, 60})};
  const StackMatch neg = matchDetections(d, labels, carConfig());
  EXPECT_EQ(neg.labelRoles[0], LabelRole::kBackground);
  EXPECT_EQ(neg.falseAlarms, 1u);
  EXPECT_EQ(neg.positives, 0u);

  MatchConfig alias = carConfig();
  alias.aliasClasses = {"van"};
  const StackMatch pos = matchDetections(d, labels, alias);
  EXPECT_EQ(pos.hits, 1u);
  EXPECT_EQ(pos.positives, 1u);

  MatchConfig ign = carConfig();
  ign.ignoreClasses = {"van"};
  const StackMatch ig = matchDetections(d, labels, ign);
  EXPECT_EQ(ig.ignored, 1u);
  EXPECT_EQ(ig.falseAlarms, 0u);
  EXPECT_EQ(ig.positives, 0u);
}

TEST(Evaluation, SecondDetectionOnOneObjectIsAFalseAlarm) {
  const Labels labels{label("car", {0, 0, 100, 100})};
  // The higher-scoring one (index 1) takes the hit, whatever the input order.
  const StackMatch m =
      matchDetections({det({0, 0, 100, 90}, 0.2), det({0, 0, 100, 100}, 0.9)}, labels, carConfig());
  EXPECT_EQ(m.hits, 1u);
  EXPECT_EQ(m.falseAlarms, 1u);
  EXPECT_EQ(m.hitBy[0], 1);
  EXPECT_EQ(m.detections[0], DetectionOutcome::kFalseAlarm);
  EXPECT_EQ(m.detections[1], DetectionOutcome::kHit);
}

TEST(Evaluation, DetectionTakesTheBestOverlappingLabel) {
  // Two cars side by side; the detection overlaps A with IoU 0.6 and B with IoU 0.667.
  const Labels labels{label("car", {0, 0, 100, 100}), label("car", {40, 0, 100, 100})};
  // det (20,0,100,100): with A: inter 80*100 / (20000-8000) = 0.667; with B: inter 80*100 -> 0.667.
  // Shift to (30,0): with A 70/130 = 0.538; with B 90/110 = 0.818 -> B.
  const StackMatch m = matchDetections({det({30, 0, 100, 100})}, labels, carConfig());
  EXPECT_EQ(m.hitBy[0], -1);
  EXPECT_EQ(m.hitBy[1], 0);
  EXPECT_EQ(m.misses, 1u);
}

TEST(Evaluation, OtherClassesDetectionsAreNotCounted) {
  const Labels labels{label("person", {0, 0, 30, 80})};
  const StackMatch m = matchDetections({det({0, 0, 30, 80}, 1, "car")}, labels, carConfig());
  EXPECT_EQ(m.labelRoles[0], LabelRole::kBackground);
  EXPECT_EQ(m.falseAlarms, 1u);  // a car detection on a person is wrong
  MatchConfig person;
  person.className = "person";
  const StackMatch p = matchDetections({det({0, 0, 30, 80}, 1, "car")}, labels, person);
  EXPECT_EQ(p.hits + p.falseAlarms, 0u);  // the car detector's output is not the person's
  EXPECT_EQ(p.misses, 1u);
}

TEST(Evaluation, CountsAndMeasures) {
  Counts c;
  StackMatch a;
  a.hits = 2; a.falseAlarms = 1; a.positives = 3; a.misses = 1;
  StackMatch b;
  b.hits = 1; b.positives = 2; b.misses = 1;
  c.add(a);
  c.add(b);
  EXPECT_EQ(c.stacks, 2u);
  EXPECT_DOUBLE_EQ(c.recall().value(), 3.0 / 5.0);
  EXPECT_DOUBLE_EQ(c.precision().value(), 3.0 / 4.0);
  EXPECT_NEAR(c.fMeasure().value(), 2 * 0.6 * 0.75 / 1.35, 1e-12);
  // Undefined cases: nothing to find, nothing detected - never a vacuous 1.
  Counts empty;
  EXPECT_FALSE(empty.recall().has_value());
  EXPECT_FALSE(empty.precision().has_value());
  EXPECT_FALSE(empty.fMeasure().has_value());
  EXPECT_EQ(formatMeasure(empty.precision()), "null");
  Counts missedAll;
  missedAll.positives = 4;
  missedAll.misses = 4;
  EXPECT_EQ(missedAll.recall(), 0.0);
  EXPECT_FALSE(missedAll.precision().has_value());
  EXPECT_EQ(missedAll.fMeasure(), 0.0);  // recall 0: F 0 whatever the precision
  Counts onlyFalseAlarms;
  onlyFalseAlarms.falseAlarms = 3;
  EXPECT_EQ(onlyFalseAlarms.precision(), 0.0);
  EXPECT_FALSE(onlyFalseAlarms.fMeasure().has_value());  // no positives: F undefined
}

TEST(Evaluation, FMeasureReproducesThePapersTables) {
  // (recall, precision, F) as printed in the paper, rounded to two decimals there.
  struct Row { double r, p, f; };
  for (const Row& row : {Row{0.97, 0.65, 0.78}, Row{0.85, 0.29, 0.43}, Row{0.94, 0.78, 0.85},
                         Row{0.55, 0.74, 0.63}, Row{0.94, 0.94, 0.94}})
    EXPECT_NEAR(fMeasure(row.r, row.p), row.f, 0.005) << row.r << " " << row.p;
  EXPECT_EQ(fMeasure(0, 0), 0.0);
}

Cascade twoLayerCascade() {
  Cascade c;
  c.className = "car";
  c.layers = {"intensity", "distance", "remission"};
  const int edge = c.addFeature({FeatureType::kEdgeHorizontal, {0, 0, 1, 1}, 0});
  const int corner = c.addFeature({FeatureType::kCornerTopLeft, {0.1, 0.1, 0.5, 0.5}, 1});
  Stage s1;
  s1.stumps = {Stump{edge, 0.5, -0.8, 0.6}, Stump{corner, 1.0, 0.9, -0.1}};  // weights 1.4, 1.0
  s1.threshold = 0;
  Stage s2;
  s2.stumps = {Stump{corner, 2.0, -0.3, 0.3}};  // weight 0.6
  s2.threshold = 0.1;
  c.stages = {s1, s2};
  return c;
}

TEST(CascadeSummary, WeightIsTheLeafDifferenceSummedPerLayer) {
  const CascadeSummary s = summarizeCascade(twoLayerCascade());
  EXPECT_EQ(s.length, 3u);
  EXPECT_EQ(s.stages, 2u);
  EXPECT_NEAR(s.layerWeight.at("intensity"), 1.4, 1e-12);
  EXPECT_NEAR(s.layerWeight.at("distance"), 1.6, 1e-12);
  EXPECT_EQ(s.layerWeight.at("remission"), 0.0);  // listed although unused
  EXPECT_NEAR(s.layerWeightShare.at("intensity"), 1.4 / 3.0, 1e-12);
  EXPECT_NEAR(s.layerWeightShare.at("distance"), 1.6 / 3.0, 1e-12);
  EXPECT_EQ(s.layerCount.at("distance"), 2u);
  EXPECT_EQ(s.cornerCount, 2u);
  EXPECT_NEAR(s.cornerShare(), 2.0 / 3.0, 1e-12);
}

TEST(CascadeSummary, CombiningAddsLengthsAndReweights) {
  Cascade camera;
  camera.layers = {"intensity"};
  const int f = camera.addFeature({FeatureType::kLineVertical, {0, 0, 1, 1}, 0});
  Stage st;
  st.stumps = {Stump{f, 0, -1, 1}};  // weight 2
  camera.stages = {st};
  const CascadeSummary both = combineSummaries({summarizeCascade(twoLayerCascade()), summarizeCascade(camera)});
  EXPECT_EQ(both.length, 4u);
  EXPECT_EQ(both.stages, 3u);
  EXPECT_NEAR(both.layerWeight.at("intensity"), 3.4, 1e-12);
  EXPECT_NEAR(both.layerWeightShare.at("intensity"), 3.4 / 5.0, 1e-12);
  EXPECT_NEAR(both.cornerShare(), 0.5, 1e-12);
}

}  // namespace
}  // namespace fusedet::boosting
