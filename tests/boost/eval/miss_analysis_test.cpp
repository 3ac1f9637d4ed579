// SPDX-License-Identifier: Apache-2.0
// Where missed objects are lost (miss_analysis.h), on a synthetic scene whose every object is
// built to be lost at one known step, and the grouping fates it relies on (grouping.h).

#include "fusedet/boost/miss_analysis.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <random>

#include "fusedet/boost/grouping.h"

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

// Two stages: stage 1 passes a window whose intensity centre is >= 50 brighter than its surround,
// stage 2 one whose distance centre is >= 5 higher than its surround.
Cascade blobCascade() {
  Cascade c;
  c.className = "car";
  c.windowWidth = 20;
  c.windowHeight = 20;
  c.layers = {"intensity", "distance"};
  const int onIntensity = c.addFeature(Feature{FeatureType::kCenterSurround, Box{0, 0, 1, 1}, 0});
  const int onDistance = c.addFeature(Feature{FeatureType::kCenterSurround, Box{0, 0, 1, 1}, 1});
  c.stages.push_back(Stage{{Stump{onIntensity, 50, -1, 1}}, 0});
  c.stages.push_back(Stage{{Stump{onDistance, 5, -1, 1}}, 0});
  return c;
}

Label car(Box box) {
  Label l;
  l.className = "car";
  l.sourceClass = "Car";
  l.box = box;
  return l;
}

// 400 x 100, dark and flat; blobs of 10 x 10 pixels at the given corners.
struct Scene {
  cv::Mat intensity = cv::Mat(100, 400, CV_8U, cv::Scalar(0));
  cv::Mat distance = cv::Mat(100, 400, CV_32F, cv::Scalar(0));
  void blob(int x, int y, bool inDistance) {
    intensity(cv::Rect(x, y, 10, 10)).setTo(255);
    if (inDistance) distance(cv::Rect(x, y, 10, 10)).setTo(10);
  }
  LayerStack stack() const {
    LayerStack s(400, 100);
    s.set(Layer{"intensity", intensity, {}});
    s.set(Layer{"distance", distance, {}});
    return s;
  }
};

DetectionSetup setupWith(int minNeighbors) {
  DetectionSetup s;
  s.scan.scaleFactor = 1.2;
  s.scan.step = 2;
  s.scan.threads = 1;
  s.group.minNeighbors = minNeighbors;
  return s;
}

MatchConfig carRules() {
  MatchConfig m;
  m.className = "car";
  m.minHeight = 15;  // the scene's objects are 20-30 px high
  m.minDetectionHeight = 15;
  return m;
}

const PositiveOutcome& outcomeOfLabel(const FrameMissAnalysis& a, std::size_t label) {
  for (const PositiveOutcome& p : a.positives)
    if (p.label == label) return p;
  throw std::runtime_error("label " + std::to_string(label) + " is not a positive");
}

}  // namespace

TEST(MissAnalysis, EachObjectIsLostAtTheStepItWasBuiltFor) {
  Scene scene;
  scene.blob(30, 40, true);    // 0: both layers: the cascade accepts windows centred on it
  scene.blob(90, 40, false);   // 1: intensity only: stage 2 rejects every window
  // 2: nothing at all: stage 1 rejects every window
  // 3: 80 x 20 (aspect 4): no square window reaches IoU 0.5
  const LayerStack stack = scene.stack();
  const Labels labels{car({20, 30, 30, 30}), car({80, 30, 30, 30}), car({140, 30, 30, 30}), car({200, 70, 80, 20})};
  const Detector det(blobCascade());

  const FrameMissAnalysis a = analyseMisses(det, stack, labels, carRules(), setupWith(1));
  ASSERT_EQ(a.positives.size(), 4u);
  EXPECT_TRUE(outcomeOfLabel(a, 0).hit);
  EXPECT_EQ(a.match.hits, 1u);

  const PositiveOutcome& noDistance = outcomeOfLabel(a, 1);
  EXPECT_FALSE(noDistance.hit);
  EXPECT_EQ(noDistance.cause, MissCause::kCascade);
  EXPECT_EQ(noDistance.deepestStage, 1);  // stage 1 passed near the blob, stage 2 rejected all
  EXPECT_GT(noDistance.candidates, 0u);
  EXPECT_EQ(noDistance.acceptedCandidates, 0u);
  EXPECT_EQ(noDistance.stageCount, 2);

  const PositiveOutcome& nothing = outcomeOfLabel(a, 2);
  EXPECT_EQ(nothing.cause, MissCause::kCascade);
  EXPECT_EQ(nothing.deepestStage, 0);

  // Best window: 41 x 41 (20 * 1.2^4 = 41.47), step 4, at y in 52..68 and x = 200: it covers the
  // 80 x 20 box's full height over 41 px: IoU = 820 / (1600 + 1681 - 820) = 0.3332; the 35 and
  // 50 px windows give 0.329 and 0.323.
  const PositiveOutcome& wide = outcomeOfLabel(a, 3);
  EXPECT_EQ(wide.cause, MissCause::kScanGeometry);
  EXPECT_NEAR(wide.bestWindowIou, 820.0 / 2461.0, 1e-12);
  EXPECT_EQ(wide.candidates, 0u);
}

TEST(MissAnalysis, AcceptedWindowsDroppedByGroupingAreGroupingLosses) {
  Scene scene;
  scene.blob(30, 40, true);
  const LayerStack stack = scene.stack();
  const Labels labels{car({20, 30, 30, 30})};
  const Detector det(blobCascade());
  const std::vector<RawHit> hits = det.scan(stack, setupWith(1).scan);
  ASSERT_FALSE(hits.empty());
  // More neighbours than there are hits: the one group is dropped.
  const int tooMany = static_cast<int>(hits.size());
  const FrameMissAnalysis a = analyseMisses(det, stack, labels, carRules(), setupWith(tooMany));
  ASSERT_EQ(a.positives.size(), 1u);
  const PositiveOutcome& p = a.positives[0];
  EXPECT_FALSE(p.hit);
  EXPECT_EQ(p.cause, MissCause::kGrouping);
  EXPECT_EQ(p.groupingLoss, GroupingLoss::kTooFewNeighbours);
  EXPECT_GT(p.acceptedCandidates, 0u);
  EXPECT_LE(p.largestGroup, tooMany);
  EXPECT_EQ(p.deepestStage, 2);  // accepted = passed every stage
  EXPECT_TRUE(a.detections.empty());
}

TEST(MissAnalysis, ADetectionBesideTheObjectIsALocalisationLoss) {
  // The blob is centred in (300, 30, 30, 30); the label lies 14 px to its right and 8 px lower.
  // Its windows with IoU >= 0.5 have the blob off their centre cell and are rejected; the
  // detections on the blob overlap it with IoU in [0.3, 0.5).
  Scene scene;
  scene.blob(310, 40, true);
  const LayerStack stack = scene.stack();
  const Labels labels{car({314, 38, 30, 30})};
  const Detector det(blobCascade());
  const DetectionSetup setup = setupWith(0);  // every accepted window is a detection
  const FrameMissAnalysis a = analyseMisses(det, stack, labels, carRules(), setup);
  ASSERT_EQ(a.positives.size(), 1u);
  const PositiveOutcome& p = a.positives[0];
  // Independent check of the premise with the scanner's own hits.
  double bestHitIou = 0;
  for (const RawHit& h : det.scan(stack, setup.scan)) bestHitIou = std::max(bestHitIou, iou(h.box, labels[0].box));
  ASSERT_GE(bestHitIou, 0.3);
  ASSERT_LT(bestHitIou, 0.5);
  EXPECT_FALSE(p.hit);
  EXPECT_EQ(p.cause, MissCause::kLocalisation);
  EXPECT_DOUBLE_EQ(p.bestDetectionIou, bestHitIou);
  EXPECT_EQ(p.acceptedCandidates, 0u);
  EXPECT_GT(p.candidates, 0u);
  EXPECT_EQ(a.match.falseAlarms, a.detections.size());  // every detection misses it
}

TEST(MissAnalysis, DetectionsEqualTheEvaluationsForEveryGrouping) {
  Scene scene;
  scene.blob(30, 40, true);
  scene.blob(150, 20, true);
  scene.blob(300, 60, false);
  const LayerStack stack = scene.stack();
  const Labels labels{car({20, 30, 30, 30}), car({135, 5, 40, 40})};
  const Detector det(blobCascade());
  for (int nb : {0, 1, 2, 3, 8}) {
    const DetectionSetup setup = setupWith(nb);
    const FrameMissAnalysis a = analyseMisses(det, stack, labels, carRules(), setup);
    const std::vector<Detection> ref = detectChain({&det}, stack, setup);
    ASSERT_EQ(a.detections.size(), ref.size()) << "min neighbours " << nb;
    for (std::size_t i = 0; i < ref.size(); ++i) {
      EXPECT_EQ(a.detections[i].box, ref[i].box);
      EXPECT_EQ(a.detections[i].score, ref[i].score);
    }
    const StackMatch m = matchDetections(ref, labels, carRules());
    EXPECT_EQ(a.match.hits, m.hits);
    EXPECT_EQ(a.match.falseAlarms, m.falseAlarms);
    std::size_t missed = 0;
    for (const PositiveOutcome& p : a.positives) missed += p.hit ? 0 : 1;
    EXPECT_EQ(missed, m.misses);
  }
}

TEST(MissAnalysis, RefusesOpenCvCascades) {
  Cascade c = blobCascade();
  c.normalization = Normalization::kOpenCvVariance;
  c.features.clear();
  c.haarFeatures.push_back(HaarFeature{{HaarRect{0, 0, 20, 20, -1.f}, HaarRect{5, 5, 10, 10, 2.f}}, 2, false});
  c.stages = {Stage{{Stump{0, 0.1, -1, 1}}, 0}};
  c.layers = {"intensity"};
  const Detector det(c);
  Scene scene;
  EXPECT_THROW(analyseMisses(det, scene.stack(), {}, carRules(), setupWith(1)), std::invalid_argument);
}

TEST(MissAnalysis, BreakdownCountsCausesAndBuckets) {
  auto outcome = [](Box box, int occlusion, double truncation, bool hit, MissCause cause) {
    PositiveOutcome p;
    p.box = box;
    p.occlusion = occlusion;
    p.truncation = truncation;
    p.hit = hit;
    p.cause = cause;
    return p;
  };
  PositiveOutcome grouped = outcome({0, 0, 60, 30}, 1, 0, false, MissCause::kGrouping);  // 30 px high, w/h 2
  grouped.groupingLoss = GroupingLoss::kTooFewNeighbours;
  grouped.largestGroup = 2;
  grouped.bestDetectionIou = 0.4;
  PositiveOutcome rejected = outcome({0, 0, 75, 50}, 0, 0.2, false, MissCause::kCascade);  // 50 px, w/h 1.5
  rejected.deepestStage = 11;
  const std::vector<std::vector<PositiveOutcome>> frames{
      {outcome({0, 0, 120, 100}, 0, 0, true, MissCause::kCascade), grouped},  // 100 px, w/h 1.2: hit
      {rejected, outcome({0, 0, 30, 30}, 2, 0, false, MissCause::kScanGeometry)}};  // 30 px, w/h 1
  const MissBreakdown b = summariseMisses(frames);
  EXPECT_EQ(b.allPositives, 4u);
  EXPECT_EQ(b.allMisses, 3u);
  auto at = [&](const std::string& name) {
    for (std::size_t k = 0; k < b.bucketNames.size(); ++k)
      if (b.bucketNames[k] == name) return k;
    throw std::runtime_error("no bucket " + name);
  };
  const auto idx = [](MissCause c) { return static_cast<std::size_t>(c); };
  EXPECT_EQ(b.total[idx(MissCause::kGrouping)], 1u);
  EXPECT_EQ(b.total[idx(MissCause::kCascade)], 1u);
  EXPECT_EQ(b.total[idx(MissCause::kScanGeometry)], 1u);
  EXPECT_EQ(b.nearDetection[idx(MissCause::kGrouping)], 1u);
  EXPECT_EQ(b.positives[at("25-39 px")], 2u);
  EXPECT_EQ(b.misses[at("25-39 px")], 2u);
  EXPECT_EQ(b.positives[at(">= 100 px")], 1u);
  EXPECT_EQ(b.misses[at(">= 100 px")], 0u);
  EXPECT_EQ(b.byCause[idx(MissCause::kCascade)][at("40-59 px")], 1u);
  EXPECT_EQ(b.byCause[idx(MissCause::kGrouping)][at("w/h >= 2")], 1u);
  EXPECT_EQ(b.positives[at("w/h 1.2-2")], 2u);  // 1.2 and 1.5
  EXPECT_EQ(b.positives[at("w/h < 1.2")], 1u);
  EXPECT_EQ(b.byCause[idx(MissCause::kScanGeometry)][at("occlusion >= 2")], 1u);
  EXPECT_EQ(b.misses[at("truncated")], 1u);
  EXPECT_EQ(b.positives[at("not truncated")], 3u);
  EXPECT_EQ(b.groupingLosses[static_cast<std::size_t>(GroupingLoss::kTooFewNeighbours)], 1u);
  ASSERT_EQ(b.tooFewByGroupSize.size(), 3u);
  EXPECT_EQ(b.tooFewByGroupSize[2], 1u);
  ASSERT_EQ(b.rejectedAtStage.size(), 12u);
  EXPECT_EQ(b.rejectedAtStage[11], 1u);  // rejected by stage 12
}

TEST(MissAnalysis, UntrainedFoldsMissEveryPositive) {
  const Labels labels{car({0, 0, 40, 30}), car({50, 0, 20, 10})};  // the second is below 25 px: ignored
  MatchConfig rules;
  rules.className = "car";
  const std::vector<PositiveOutcome> u = untrainedOutcomes(labels, rules);
  ASSERT_EQ(u.size(), 1u);
  EXPECT_EQ(u[0].label, 0u);
  EXPECT_FALSE(u[0].hit);
  EXPECT_EQ(u[0].cause, MissCause::kUntrained);
}

TEST(GroupingFates, EveryHitKnowsItsDetectionOrWhyItHasNone) {
  LayerStack stack(640, 480);
  std::mt19937 rng(3);
  for (int round = 0; round < 30; ++round) {
    std::vector<RawHit> hits;
    for (int c = 0; c < 6; ++c) {
      const int x = int(rng() % 500), y = int(rng() % 300), s = 20 + int(rng() % 80), n = 1 + int(rng() % 6);
      for (int i = 0; i < n; ++i)
        hits.push_back(RawHit{Box{double(x + int(rng() % 5)), double(y + int(rng() % 5)), double(s), double(s)},
                              double(rng() % 100), 0});
    }
    for (int nb : {0, 1, 3}) {
      GroupParams p;
      p.minNeighbors = nb;
      std::vector<HitFate> fates;
      const std::vector<Detection> with = groupHits(hits, p, "car", stack, &fates);
      const std::vector<Detection> without = groupHits(hits, p, "car", stack);
      ASSERT_EQ(with.size(), without.size());
      ASSERT_EQ(fates.size(), hits.size());
      std::vector<int> members(with.size(), 0);
      for (const HitFate& f : fates) {
        if (f.detection >= 0) {
          EXPECT_EQ(f.outcome, HitFate::Outcome::kKept);
          ++members[static_cast<std::size_t>(f.detection)];
        } else if (f.outcome == HitFate::Outcome::kTooFewNeighbours) {
          EXPECT_LE(f.groupSize, nb);
        } else {
          EXPECT_EQ(f.outcome, HitFate::Outcome::kInsideBiggerGroup);
          EXPECT_GT(f.groupSize, nb);
        }
      }
      // A detection's score is the size of its group (nb > 0): exactly the hits that name it.
      for (std::size_t d = 0; d < with.size(); ++d) EXPECT_EQ(members[d], nb > 0 ? int(with[d].score) : 1);
    }
  }
}
