// The merge of a model's cascades (aspect_cascades.h) on hand-made detections and hits.
#include "fusedet/boost/aspect_cascades.h"

#include <gtest/gtest.h>

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

constexpr auto kScore = GroupParams::AspectMerge::kByScore;
constexpr auto kFirst = GroupParams::AspectMerge::kFirstCascadeFirst;

Detection det(double x, double w, double score) {
  Detection d;
  d.className = "car";
  d.box = Box{x, 0, w, 20};
  d.score = score;
  return d;
}

Cascade oneStump(int width) {
  Cascade c;
  c.className = "car";
  c.windowWidth = width;
  c.windowHeight = 20;
  c.layers = {"intensity"};
  const int f = c.addFeature(Feature{FeatureType::kEdgeHorizontal, Box{0, 0, 1, 1}, 0});
  c.stages.push_back(Stage{{Stump{f, 0, 1, 1}}, 0});
  return c;
}

std::vector<RawHit> around(double x, double w, int n) {
  std::vector<RawHit> out;
  for (int i = 0; i < n; ++i) out.push_back(RawHit{Box{x + i % 2, 0, w, 20}, 1.0, 0});
  return out;
}

}  // namespace

// Cascade 0 (1.5:1) found A at x 0 (score 5) and B at x 100 (score 2); cascade 1 (2.4:1) found C
// over A (IoU 600/960 = 0.625, score 4), D over B (IoU 0.625, score 6) and E alone (score 1).
// By score: D kept, A kept, C dropped (A), B dropped (D), E kept. Output in cascade order: A, D, E.
TEST(AspectCascades, MergeKeepsTheBetterOfOverlappingDetectionsOfDifferentCascades) {
  const std::vector<std::vector<Detection>> per = {{det(0, 30, 5), det(100, 30, 2)},
                                                   {det(0, 48, 4), det(95, 48, 6), det(200, 48, 1)}};
  const MergedDetections m = mergeCascadeDetections(per, 0.5, kScore);
  ASSERT_EQ(m.detections.size(), 3u);
  EXPECT_EQ(m.detections[0].box, per[0][0].box);
  EXPECT_EQ(m.detections[1].box, per[1][1].box);
  EXPECT_EQ(m.detections[2].box, per[1][2].box);
  EXPECT_EQ(m.kept[0], (std::vector<int>{0, 1}));     // B went to D
  EXPECT_EQ(m.kept[1], (std::vector<int>{0, 1, 2}));  // C went to A
  // Above the overlap 0.625 nothing is dropped.
  EXPECT_EQ(mergeCascadeDetections(per, 0.7, kScore).detections.size(), 5u);
  // The model's own cascade first: A and B stay, C and D (over them) go, E is added.
  const MergedDetections first = mergeCascadeDetections(per, 0.5, kFirst);
  ASSERT_EQ(first.detections.size(), 3u);
  EXPECT_EQ(first.detections[1].box, per[0][1].box);
  EXPECT_EQ(first.detections[2].box, per[1][2].box);
  EXPECT_EQ(first.kept[1], (std::vector<int>{0, 1, 2}));  // C went to A, D to B
  // Equal scores: the earlier cascade wins.
  const MergedDetections tie = mergeCascadeDetections({{det(0, 30, 3)}, {det(0, 48, 3)}}, 0.5, kScore);
  ASSERT_EQ(tie.detections.size(), 1u);
  EXPECT_EQ(tie.detections[0].box.w, 30);
}

TEST(AspectCascades, DetectionsOfOneCascadeNeverSuppressEachOther) {
  const MergedDetections m = mergeCascadeDetections({{det(0, 30, 3), det(2, 30, 1)}, {}}, 0.5, kScore);
  EXPECT_EQ(m.detections.size(), 2u);
  EXPECT_EQ(m.kept[0], (std::vector<int>{0, 1}));
}

TEST(AspectCascades, AModelWithoutAspectCascadesGroupsAsGroupHits) {
  const LayerStack stack(300, 100);
  std::vector<RawHit> hits = around(10, 30, 5);
  for (const RawHit& h : around(150, 30, 2)) hits.push_back(h);  // too few neighbours
  GroupParams g;
  const std::vector<Detection> want = groupHits(hits, g, "car", stack);
  std::vector<std::vector<HitFate>> fates;
  const std::vector<Detection> got = groupModelHits(oneStump(30), {hits}, g, stack, &fates);
  ASSERT_EQ(got.size(), want.size());
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].box, want[0].box);
  EXPECT_EQ(got[0].score, 5);
  ASSERT_EQ(fates.size(), 1u);
  EXPECT_EQ(fates[0][0].detection, 0);
  EXPECT_EQ(fates[0][6].outcome, HitFate::Outcome::kTooFewNeighbours);
  EXPECT_THROW(groupModelHits(oneStump(30), {hits, hits}, g, stack), std::invalid_argument);
}

// Merged by score, the wide cascade's group (6 hits) outscores the base cascade's (4 hits) on the
// same car: the base group's hits now point to the wide detection, detection 0 of the output. By
// default (the model's own cascade first) the base group stays and the wide one points to it.
TEST(AspectCascades, FatesOfADroppedGroupPointToTheDetectionThatReplacedIt) {
  Cascade model = oneStump(30);
  model.aspectCascades.push_back(oneStump(48));
  const LayerStack stack(300, 100);
  GroupParams g;
  std::vector<std::vector<HitFate>> firstFates;
  const std::vector<Detection> own = groupModelHits(model, {around(0, 30, 4), around(0, 48, 6)}, g, stack, &firstFates);
  ASSERT_EQ(own.size(), 1u);
  EXPECT_EQ(own[0].box.w, 30);
  EXPECT_EQ(firstFates[1][0].detection, 0);
  g.aspectMerge = kScore;
  std::vector<std::vector<HitFate>> fates;
  const std::vector<Detection> got =
      groupModelHits(model, {around(0, 30, 4), around(0, 48, 6)}, g, stack, &fates);
  ASSERT_EQ(got.size(), 1u);
  EXPECT_EQ(got[0].box.w, 48);
  EXPECT_EQ(got[0].score, 6);
  ASSERT_EQ(fates.size(), 2u);
  for (const auto& perCascade : fates)
    for (const HitFate& f : perCascade) EXPECT_EQ(f.detection, 0);
  // Merge overlap 0.7 (> IoU 0.625): both stay, the base cascade's first.
  g.aspectMergeIou = 0.7;
  const std::vector<Detection> both = groupModelHits(model, {around(0, 30, 4), around(0, 48, 6)}, g, stack);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_EQ(both[0].box.w, 30);
}
