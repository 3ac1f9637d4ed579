// SPDX-License-Identifier: Apache-2.0
// The teacher of fusedet autolabel: the score and laser-veto rules on a hand-made stack, merging
// with human labels, and the real Yolo-Fastest-XL on a KITTI frame against a plain evaluation of
// the same network on the frame's PNG.

#include <gtest/gtest.h>

#include <filesystem>
#include <opencv2/imgcodecs.hpp>

#include "fusedet/fusion/datasets/kitti_import.h"
#include "fusedet/fusion/datasets/teacher_labels.h"

namespace fusedet::fusion {
namespace {
namespace fs = std::filesystem;

Detection detection(const std::string& cls, double score, double x, double y, double w, double h) {
  Detection d;
  d.className = cls;
  d.score = score;
  d.box = Box{x, y, w, h};
  return d;
}

// 200 x 100 reference; distance layer at half size. The laser measures the lower half of the image
// (rows 50..99 in reference pixels) except a hole at x 120..159, y 60..89 (reference pixels).
LayerStack laserStack() {
  LayerStack s(200, 100);
  cv::Mat valid(50, 100, CV_8U, cv::Scalar(0));
  valid.rowRange(25, 50).setTo(255);
  valid(cv::Rect(60, 30, 20, 15)).setTo(0);
  s.set(Layer{"distance", cv::Mat(50, 100, CV_32F, cv::Scalar(10.0f)), valid});
  return s;
}

TEST(TeacherLabels, ScoresDecideLabelIgnoreOrNothing) {
  const LayerStack s = laserStack();
  TeacherRule rule;  // 0.5 label, 0.25 ignore
  TeacherCounts counts;
  const Labels labels = teacherLabels({detection("car", 0.9, 10, 60, 30, 20), detection("person", 0.3, 50, 60, 10, 30),
                                       detection("bike", 0.1, 80, 60, 20, 20), detection("truck", 0.9, 0, 50, 50, 50)},
                                      s, rule, counts);
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_EQ(labels[0].className, "car");
  EXPECT_FALSE(labels[0].ignore);
  EXPECT_EQ(labels[0].origin, "teacher");
  EXPECT_DOUBLE_EQ(labels[0].box.w, 30);
  EXPECT_EQ(labels[1].className, "person");
  EXPECT_TRUE(labels[1].ignore);
  EXPECT_EQ(counts.labels, 1u);
  EXPECT_EQ(counts.ignoreRegions, 1u);
}

TEST(TeacherLabels, TheLaserVetoesABoxWithoutDepthWhereDepthIsExpected) {
  const LayerStack s = laserStack();
  // Inside the hole (x 124..155, y 64..85): ring measured, inside not -> vetoed.
  const DepthCoverage hole = depthCoverage(s, Box{124, 64, 32, 22});
  EXPECT_DOUBLE_EQ(hole.inside, 0);
  EXPECT_GT(hole.around, 0.5);
  // On the sky (upper half): nothing measured around either -> kept (no depth expected there).
  const DepthCoverage sky = depthCoverage(s, Box{20, 10, 20, 16});
  EXPECT_DOUBLE_EQ(sky.inside, 0);
  EXPECT_LT(sky.around, 0.5);
  TeacherRule rule;
  TeacherCounts counts;
  Labels labels = teacherLabels({detection("car", 0.9, 124, 64, 32, 22), detection("car", 0.9, 20, 10, 20, 16),
                                 detection("car", 0.9, 20, 60, 30, 30)},
                                s, rule, counts);
  ASSERT_EQ(labels.size(), 2u);
  EXPECT_DOUBLE_EQ(labels[0].box.x, 20);
  EXPECT_DOUBLE_EQ(labels[0].box.y, 10);
  EXPECT_DOUBLE_EQ(labels[1].box.y, 60);
  EXPECT_EQ(counts.vetoed, 1u);
  rule.laserVeto = false;
  EXPECT_EQ(teacherLabels({detection("car", 0.9, 124, 64, 32, 22)}, s, rule, counts).size(), 1u);
  // No distance layer at all: nothing to veto with.
  rule.laserVeto = true;
  EXPECT_EQ(teacherLabels({detection("car", 0.9, 124, 64, 32, 22)}, LayerStack(200, 100), rule, counts).size(), 1u);
}

TEST(TeacherLabels, MergingKeepsHumansReplacesTheOldTeacherAndSkipsBoxesUnderHumans) {
  Label human;
  human.className = "car";
  human.box = Box{10, 10, 40, 20};
  Label oldTeacher = human;
  oldTeacher.origin = "teacher";
  oldTeacher.box = Box{100, 10, 10, 10};
  Label overHuman = human;
  overHuman.origin = "teacher";
  overHuman.box = Box{12, 10, 40, 20};  // IoU 38/42 with the human box
  Label fresh = human;
  fresh.origin = "teacher";
  fresh.box = Box{150, 50, 20, 20};
  TeacherRule rule;
  TeacherCounts counts;
  counts.labels = 2;  // as teacherLabels counted the two taught boxes
  const Labels merged = mergeTeacherLabels({human, oldTeacher}, {overHuman, fresh}, rule, counts);
  ASSERT_EQ(merged.size(), 2u);
  EXPECT_EQ(merged[0].origin, "human");
  EXPECT_DOUBLE_EQ(merged[1].box.x, 150);
  EXPECT_EQ(counts.underHuman, 1u);
  EXPECT_EQ(counts.labels, 1u);
  rule.replaceHuman = true;
  const Labels teacherOnly = mergeTeacherLabels({human, oldTeacher}, {overHuman, fresh}, rule, counts);
  ASSERT_EQ(teacherOnly.size(), 2u);
  EXPECT_EQ(teacherOnly[0].origin, "teacher");
}

TEST(TeacherLabels, YoloFastestOnAKittiFrameGivesThePlainEvaluationsBoxes) {
  const fs::path models = FUSEDET_NETWORKS_DIR;
  const fs::path kitti = fs::path(FUSEDET_DATA_DIR) / "kitti";
  const NetworkSpec spec{NetworkKind::darknet,
                         {models / "yolo-fastest-1.1-xl.cfg", models / "yolo-fastest-1.1-xl.weights"},
                         cv::Size(832, 256),
                         1};
  Network network(spec);
  const KittiFrame frame = readKittiFrame(kitti, "000000");
  const DatasetItem item = fuseKittiFrame(frame, "kitti", ProjectionConfig{});
  TeacherRule rule;
  rule.laserVeto = false;
  TeacherCounts counts;
  const Labels labels = teachStack(network, item.stack, rule, counts);

  // The plain evaluation: the frame's PNG straight from the disk, the same network and decoder.
  CocoDetectionRule plain;
  plain.minScore = rule.uncertainScore;
  const std::vector<Detection> expected = cocoDetections(network.run(cv::imread((kitti / "image_2" / "000000.png").string())), plain);
  ASSERT_FALSE(expected.empty());
  ASSERT_EQ(labels.size(), expected.size());
  for (std::size_t i = 0; i < labels.size(); ++i) {
    EXPECT_EQ(labels[i].className, expected[i].className);
    EXPECT_EQ(labels[i].ignore, expected[i].score < rule.minScore);
    EXPECT_NEAR(labels[i].box.x, expected[i].box.x, 1e-9);
    EXPECT_NEAR(labels[i].box.h, expected[i].box.h, 1e-9);
  }
  EXPECT_GE(counts.labels, 1u);  // at least one confident car on frame 000000 (KITTI labels two cars and a van)
}

}  // namespace
}  // namespace fusedet::fusion
