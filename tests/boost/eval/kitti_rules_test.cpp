// SPDX-License-Identifier: Apache-2.0
// The KITTI devkit's 2D rules, average precision, bootstrap intervals and the split rules, on
// worked examples whose answers are computed by hand in the comments.

#include <gtest/gtest.h>

#include <cmath>

#include "fusedet/boost/bootstrap.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/boost/learning_curve.h"
#include "fusedet/boost/precision_recall.h"

namespace fusedet::boosting {
namespace {

Label label(std::string cls, std::string source, Box box, bool ignore = false) {
  Label l;
  l.className = std::move(cls);
  l.sourceClass = std::move(source);
  l.box = box;
  l.ignore = ignore;
  return l;
}

Detection det(Box box, double score = 1, std::string cls = "") {
  Detection d;
  d.className = std::move(cls);
  d.box = box;
  d.score = score;
  return d;
}

TEST(KittiRules, NeighbourClassesAreIgnoredLabels) {
  // As the importer writes them: Van is a class of its own, Person_sitting an ignore-flagged label.
  const Labels labels{label("van", "Van", {0, 0, 80, 60}), label("", "Person_sitting", {200, 0, 30, 70}, true)};
  const std::vector<Detection> onVan{det({0, 0, 80, 60})}, onSitting{det({200, 0, 30, 70})};
  // Car: a detection exactly on the van is neither hit nor false alarm; the van is no miss.
  const StackMatch car = matchDetections(onVan, labels, matchConfigFor("car"));
  EXPECT_EQ(car.labelRoles[0], LabelRole::kIgnoredLabel);
  EXPECT_EQ(car.ignored, 1u);
  EXPECT_EQ(car.falseAlarms + car.hits + car.misses, 0u);
  // With the van as a hard negative the same detection is a false alarm.
  EXPECT_EQ(matchDetections(onVan, labels, matchConfigFor("car", VanPolicy::kNegative)).falseAlarms, 1u);
  // Person: Person_sitting is the neighbour (ignored); for car it is just another object (false alarm).
  const StackMatch person = matchDetections(onSitting, labels, matchConfigFor("person"));
  EXPECT_EQ(person.labelRoles[1], LabelRole::kIgnoredLabel);
  EXPECT_EQ(person.ignored, 1u);
  EXPECT_EQ(matchDetections(onSitting, labels, matchConfigFor("car")).falseAlarms, 1u);
  // Bike has no neighbour: the van is background.
  EXPECT_EQ(matchDetections(onVan, labels, matchConfigFor("bike")).falseAlarms, 1u);
}

TEST(KittiRules, TruckTramMiscAreFalseAlarmsDontCareAbsorbs) {
  const Labels labels{label("", "Truck", {0, 0, 100, 80}, true), label("", "Tram", {200, 0, 100, 80}, true),
                      label("", "Misc", {400, 0, 100, 80}, true), label("", "DontCare", {600, 0, 100, 80}, true)};
  const MatchConfig m = matchConfigFor("car");
  const StackMatch s = matchDetections(
      {det({0, 0, 100, 80}), det({200, 0, 100, 80}), det({400, 0, 100, 80}), det({610, 10, 60, 60})}, labels, m);
  EXPECT_EQ(s.labelRoles[0], LabelRole::kBackground);
  EXPECT_EQ(s.labelRoles[3], LabelRole::kIgnoreRegion);
  EXPECT_EQ(s.falseAlarms, 3u);
  EXPECT_EQ(s.ignored, 1u);  // the one inside DontCare (coverage 1)
}

// The devkit's minimum overlap: 0.7 for car, 0.5 for pedestrian and cyclist. A 100 x 50 label and
// a detection shifted right by 25 px: IoU = (75 x 50) / (125 x 50) = 0.6, a hit for person and bike
// but a false alarm and a miss for car; shifted by 15 px: IoU = 85 / 115 = 0.739, a hit for car.
TEST(KittiRules, MinimumOverlapIsPointSevenForCarAndPointFiveForPersonAndBike) {
  EXPECT_EQ(kittiMinOverlap("car"), 0.7);
  EXPECT_EQ(kittiMinOverlap("person"), 0.5);
  EXPECT_EQ(kittiMinOverlap("bike"), 0.5);
  EXPECT_EQ(matchConfigFor("car").minIou, 0.7);
  EXPECT_EQ(matchConfigFor("car", VanPolicy::kIgnore, 0.5).minIou, 0.5);  // --min-iou 0.5 (PASCAL)
  for (const std::string cls : {"car", "person", "bike"}) {
    const Labels labels{label(cls, cls, {100, 50, 100, 50})};
    const StackMatch at06 = matchDetections({det({125, 50, 100, 50})}, labels, matchConfigFor(cls));
    const StackMatch at074 = matchDetections({det({115, 50, 100, 50})}, labels, matchConfigFor(cls));
    const bool car = cls == "car";
    EXPECT_EQ(at06.hits, car ? 0u : 1u) << cls;
    EXPECT_EQ(at06.falseAlarms, car ? 1u : 0u) << cls;
    EXPECT_EQ(at06.misses, car ? 1u : 0u) << cls;
    EXPECT_EQ(at074.hits, 1u) << cls;
  }
  // DontCare absorbs at the class's overlap too (intersection over the detection's area):
  // 0.6 of the detection inside absorbs it for person, not for car.
  const Labels dc{label("", "DontCare", {0, 0, 60, 100}, true)};
  EXPECT_EQ(matchDetections({det({0, 0, 100, 100})}, dc, matchConfigFor("person")).falseAlarms, 0u);
  EXPECT_EQ(matchDetections({det({0, 0, 100, 100})}, dc, matchConfigFor("car")).falseAlarms, 1u);
}

TEST(KittiRules, DetectionsBelow25PixelsAreIgnored) {
  const Labels labels{label("car", "Car", {0, 0, 40, 30})};
  // 24 px high, far from any label: ignored, not a false alarm.
  const StackMatch low = matchDetections({det({300, 0, 30, 24})}, labels, matchConfigFor("car"));
  EXPECT_EQ(low.ignored, 1u);
  EXPECT_EQ(low.falseAlarms, 0u);
  EXPECT_EQ(low.misses, 1u);
  // 25 px: counted.
  EXPECT_EQ(matchDetections({det({300, 0, 30, 25})}, labels, matchConfigFor("car")).falseAlarms, 1u);
}

TEST(KittiRules, TrainingLabelsFollowTheEvaluationRoles) {
  const Labels labels{label("car", "Car", {0, 0, 50, 40}), label("van", "Van", {100, 0, 60, 50}),
                      label("", "Truck", {200, 0, 80, 60}, true), label("", "DontCare", {300, 0, 50, 50}, true)};
  const Labels t = trainingLabels(labels, matchConfigFor("car"));
  ASSERT_EQ(t.size(), 3u);  // the truck is negative material: removed
  EXPECT_FALSE(t[0].ignore);
  EXPECT_TRUE(t[1].ignore);  // the van: neither positive nor negative
  EXPECT_EQ(t[2].sourceClass, "DontCare");
}

// Four positives in two frames; detections ranked 0.9 hit, 0.8 false alarm, 0.7 hit, 0.6 hit.
std::vector<FrameOutcome> workedFrames() {
  FrameOutcome a, b;
  a.positives = 2;
  a.detections = {{0.9, true}, {0.6, true}};
  b.positives = 2;
  b.detections = {{0.8, false}, {0.7, true}};
  return {a, b};
}

TEST(AveragePrecision, WorkedExample) {
  const auto frames = workedFrames();
  const auto curve = precisionRecallCurve(allFrames(frames));
  // Points (recall, precision): (1/4, 1), (1/4, 1/2), (2/4, 2/3), (3/4, 3/4).
  ASSERT_EQ(curve.size(), 4u);
  EXPECT_DOUBLE_EQ(curve[1].precision, 0.5);
  EXPECT_DOUBLE_EQ(curve[2].precision, 2.0 / 3.0);
  EXPECT_DOUBLE_EQ(curve[3].recall, 0.75);
  // 40 points r = k/40: k 1..10 (r <= 0.25) -> max precision at recall >= r = 1; k 11..30
  // (0.25 < r <= 0.75) -> 0.75; k 31..40 -> nothing reaches r -> 0. AP = (10 + 20 * 0.75) / 40.
  EXPECT_NEAR(averagePrecision(allFrames(frames)).value(), 25.0 / 40.0, 1e-12);
  // 11 points r = 0, 0.1, ..., 1: r 0, 0.1, 0.2 -> 1; r 0.3..0.7 -> 0.75; r 0.8..1 -> 0.
  EXPECT_NEAR(averagePrecision(allFrames(frames), ApRule::kPascal11).value(), (3 + 5 * 0.75) / 11, 1e-12);
  // F at the operating point: 3 hits, 1 false alarm, 4 positives: R 0.75, P 0.75.
  EXPECT_NEAR(countsOf(allFrames(frames)).fMeasure().value(), 0.75, 1e-12);
}

TEST(AveragePrecision, TiesEnterTogetherAndUndefinedCases) {
  FrameOutcome f;
  f.positives = 1;
  f.detections = {{3, false}, {3, true}};  // one threshold: P 1/2, R 1
  const std::vector<FrameOutcome> v{f};
  const auto curve = precisionRecallCurve(allFrames(v));
  ASSERT_EQ(curve.size(), 1u);
  EXPECT_DOUBLE_EQ(curve[0].precision, 0.5);
  EXPECT_NEAR(averagePrecision(allFrames(v)).value(), 0.5, 1e-12);
  FrameOutcome none;  // positives, no detection: AP 0
  none.positives = 2;
  EXPECT_EQ(averagePrecision(allFrames(std::vector<FrameOutcome>{none})), 0.0);
  FrameOutcome nothing;  // nothing to find: AP undefined
  nothing.detections = {{1, false}};
  EXPECT_FALSE(averagePrecision(allFrames(std::vector<FrameOutcome>{nothing})).has_value());
}

TEST(Bootstrap, IntervalOfAMeanMatchesTheNormalApproximation) {
  // 100 frames, half with value 1: the mean of a resample has sd sqrt(0.25 / 100) = 0.05, so the
  // 95 % interval is about 0.5 -+ 0.098.
  const auto mean = [](const std::vector<std::size_t>& idx) -> std::optional<double> {
    double s = 0;
    for (std::size_t i : idx) s += (i % 2 == 0) ? 1.0 : 0.0;
    return s / static_cast<double>(idx.size());
  };
  const auto iv = bootstrapInterval(100, mean, {2000, 7, 0.95});
  ASSERT_TRUE(iv.has_value());
  EXPECT_NEAR(iv->lo, 0.402, 0.03);
  EXPECT_NEAR(iv->hi, 0.598, 0.03);
  EXPECT_EQ(iv->resamples, 2000u);
  // Same seed, same interval.
  const auto again = bootstrapInterval(100, mean, {2000, 7, 0.95});
  EXPECT_EQ(again->lo, iv->lo);
  // A measure undefined everywhere gives no interval.
  EXPECT_FALSE(bootstrapInterval(5, [](const auto&) { return std::optional<double>(); }).has_value());
}

TEST(Bootstrap, Verdicts) {
  EXPECT_EQ(verdict(Interval{0.01, 0.2, 10}), "holds");
  EXPECT_EQ(verdict(Interval{-0.2, -0.01, 10}), "contradicted");
  EXPECT_EQ(verdict(Interval{-0.1, 0.2, 10}), "not shown");
  EXPECT_EQ(verdict(std::nullopt), "not shown");
}

TEST(DataSplit, LeaveOneGroupOutAndDealtFolds) {
  const std::vector<std::string> g{"b", "a", "b", "c", "a"};
  const auto lodo = crossGroupFolds(g);
  ASSERT_EQ(lodo.size(), 3u);
  EXPECT_EQ(lodo[0].testGroups, std::vector<std::string>{"a"});
  EXPECT_EQ(lodo[0].test, (std::vector<std::size_t>{1, 4}));
  EXPECT_EQ(lodo[0].train, (std::vector<std::size_t>{0, 2, 3}));
  EXPECT_EQ(lodo[2].test, (std::vector<std::size_t>{3}));
  // Two folds: a -> 0, b -> 1, c -> 0.
  const auto two = crossGroupFolds(g, 2);
  ASSERT_EQ(two.size(), 2u);
  EXPECT_EQ(two[0].testGroups, (std::vector<std::string>{"a", "c"}));
  EXPECT_EQ(two[0].test, (std::vector<std::size_t>{1, 3, 4}));
  EXPECT_THROW(crossGroupFolds({"a", "a"}), std::invalid_argument);
}

TEST(DataSplit, LearningCurveSubsetsAreNestedAndSeeded) {
  std::vector<std::string> g;
  for (char c = 'a'; c <= 'h'; ++c) g.push_back(std::string(1, c));
  const Fold f = crossGroupFolds(g)[0];  // tests "a", trains b..h
  const Fold one = learningCurveFold(f, g, 1, 3), three = learningCurveFold(f, g, 3, 3);
  EXPECT_EQ(trainingGroupCount(one, g), 1u);
  EXPECT_EQ(trainingGroupCount(three, g), 3u);
  EXPECT_NE(std::find(three.train.begin(), three.train.end(), one.train[0]), three.train.end());
  EXPECT_EQ(learningCurveFold(f, g, 3, 3).train, three.train);
  EXPECT_EQ(learningCurveFold(f, g, 99, 3).train, f.train);
  EXPECT_EQ(three.test, f.test);
}

// Training frames taken until they hold N positives: 10 frames of fold "a"'s training side with
// 0, 3, 1, 0, 2, 5, 0, 1, 4, 2 positives (18 in all).
TEST(DataSplit, LearningPositivesSubsetsHoldNAreNestedAndSeeded) {
  std::vector<std::string> g{"a", "a"};
  std::vector<std::size_t> pos{7, 7};  // the held-out frames: never taken
  const std::size_t counts[] = {0, 3, 1, 0, 2, 5, 0, 1, 4, 2};
  for (std::size_t i = 0; i < 10; ++i) {
    g.push_back(i < 5 ? "b" : "c");
    pos.push_back(counts[i]);
  }
  const Fold f = crossGroupFolds(g)[0];  // tests "a" (items 0, 1), trains items 2..11
  ASSERT_EQ(f.train.size(), 10u);
  const auto held = [&](const Fold& x) {
    std::size_t n = 0;
    for (std::size_t i : x.train) n += pos[i];
    return n;
  };
  std::vector<std::size_t> previous;
  for (std::size_t n : {1u, 4u, 8u, 12u, 17u}) {
    const Fold s = learningPositivesFold(f, pos, n, 7);
    EXPECT_EQ(s.test, f.test);
    EXPECT_TRUE(std::is_sorted(s.train.begin(), s.train.end()));
    EXPECT_GE(held(s), n);
    for (std::size_t i : s.train) EXPECT_GE(i, 2u);  // training items only
    // Nested: the smaller subset's items are all here.
    for (std::size_t i : previous) EXPECT_NE(std::find(s.train.begin(), s.train.end(), i), s.train.end());
    previous = s.train;
    EXPECT_EQ(learningPositivesFold(f, pos, n, 7).train, s.train);  // seeded
  }
  // The minimal-prefix rule checked by replaying the shuffle's order: the items of the n = 1
  // subset hold at least one positive, and all but one of them hold none.
  const Fold one = learningPositivesFold(f, pos, 1, 7);
  std::size_t withPositives = 0;
  for (std::size_t i : one.train) withPositives += pos[i] > 0 ? 1 : 0;
  EXPECT_EQ(withPositives, 1u);
  EXPECT_EQ(learningPositivesFold(f, pos, 18, 7).train, f.train);  // exactly all
  EXPECT_EQ(learningPositivesFold(f, pos, 99, 7).train, f.train);
  EXPECT_EQ(learningPositivesFold(f, pos, 0, 7).train, f.train);   // 0 = all
  bool anotherSeedDiffers = false;
  for (std::uint64_t seed = 1; seed < 20; ++seed)
    anotherSeedDiffers |= learningPositivesFold(f, pos, 4, seed).train != learningPositivesFold(f, pos, 4, 7).train;
  EXPECT_TRUE(anotherSeedDiffers);
  // The drive curve's shuffle is not changed by the positives' one (cached fold models stay valid).
  const Fold drives = learningCurveFold(f, g, 1, 3);
  EXPECT_EQ(trainingGroupCount(drives, g), 1u);
}

// Positives, drives and distinct objects of a fold's training items, counted by hand: item 0
// (drive d1) holds a car of track 3 and a car of track 4 too small to be a positive (20 px);
// item 1 (d1) track 3 again and a car without a track (an object-benchmark label); item 2 (d2)
// a van and a DontCare; item 3 (held out) a car.
TEST(LearningCurve, PositivesDrivesAndDistinctObjects) {
  MatchConfig m;
  m.className = "car";
  const auto car = [](double h) { return label("car", "Car", {0, 0, 40, h}); };
  const std::vector<Labels> labels = {{car(40), car(20)},
                                      {car(50), car(30)},
                                      {label("van", "Van", {0, 0, 40, 40}), label("DontCare", "DontCare", {0, 0, 9, 9}, true)},
                                      {car(60)}};
  const std::vector<std::string> drive = {"d1", "d1", "d2", "d3"};
  const std::vector<std::vector<std::string>> objects = {{"d1/track 3", "d1/track 4"}, {"d1/track 3"}, {}, {"x"}};
  EXPECT_EQ(positivesPerItem(labels, m), (std::vector<std::size_t>{1, 2, 0, 1}));
  Fold f;
  f.train = {0, 1, 2};
  f.test = {3};
  const TrainingSetCount c = countTrainingSet(f, labels, drive, objects, m);
  EXPECT_EQ(c.items, 3u);
  EXPECT_EQ(c.positives, 3u);  // 40, 50 and 30 px cars; the 20 px one is below moderate
  EXPECT_EQ(c.groups, 2u);     // d1, d2
  EXPECT_EQ(c.objects, 2u);    // track 3 (twice) + the unnamed 30 px car; track 4 is the ignored one
  Fold none;
  EXPECT_EQ(countTrainingSet(none, labels, drive, objects, m).objects, 0u);
  f.train = {9};
  EXPECT_THROW(countTrainingSet(f, labels, drive, objects, m), std::out_of_range);
}

TEST(DataSplit, SplitByFrameWithTrainOnlyGroups) {
  std::vector<DatasetEntry> e;
  for (int i = 0; i < 6; ++i) e.push_back({"x/" + std::to_string(i), "x"});
  for (int i = 0; i < 3; ++i) e.push_back({"y/" + std::to_string(i), "y"});
  const Split s = splitByFrame(e, 0.5, {"y"});
  EXPECT_EQ(s.train.size(), 3u + 3u);  // half of x, all of y
  EXPECT_EQ(s.test.front().id, "x/3");
  EXPECT_EQ(firstTestFrame(52), 35u);  // round(52 * 2/3)
}

TEST(CrossValidation, TrainingKeyChangesWithConfigAndItems) {
  TrainingConfig a;
  TrainingConfig b = a;
  b.maxStages = a.maxStages + 1;
  EXPECT_EQ(trainingKey(a, {"x/1", "x/2"}), trainingKey(a, {"x/1", "x/2"}));
  EXPECT_NE(trainingKey(a, {"x/1", "x/2"}), trainingKey(b, {"x/1", "x/2"}));
  EXPECT_NE(trainingKey(a, {"x/1", "x/2"}), trainingKey(a, {"x/1"}));
  EXPECT_NE(trainingKey(a, {"x/12"}), trainingKey(a, {"x/1", "2"}));
  EXPECT_EQ(trainingKey(a, {}).size(), 16u);
  // Ignore classes change the key; without them the description names none.
  EXPECT_EQ(describeTrainingConfig(a).find("ignore_classes"), std::string::npos);
  TrainingConfig vans = a;
  vans.samples.ignoreClasses = neighbourClasses("car");
  EXPECT_NE(trainingKey(a, {"x/1"}), trainingKey(vans, {"x/1"}));
}

}  // namespace
}  // namespace fusedet::boosting
