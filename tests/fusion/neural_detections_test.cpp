// SPDX-License-Identifier: Apache-2.0
// COCO rows -> car, person, bike detections (fusion/neural/coco_detections.h) on hand-written
// anchor rows: the score threshold, NMS within a class (not across), a rider on a bicycle
// becoming one bike with the union box and the person's score, a lone bicycle dropped.

#include <gtest/gtest.h>

#include <algorithm>

#include "fusedet/fusion/neural/coco_detections.h"

namespace fusedet::fusion {
namespace {

// One row per (box, person, bicycle, car) score.
Anchors rows(const std::vector<std::pair<Box, std::array<float, 3>>>& r) {
  Anchors a;
  a.scores = cv::Mat(static_cast<int>(r.size()), 3, CV_32F);
  for (std::size_t i = 0; i < r.size(); ++i) {
    a.boxes.push_back(r[i].first);
    a.objectness.push_back(1);
    for (int c = 0; c < 3; ++c) a.scores.at<float>(static_cast<int>(i), c) = r[i].second[static_cast<std::size_t>(c)];
  }
  return a;
}

std::vector<Detection> ofClass(const std::vector<Detection>& d, const std::string& cls) {
  std::vector<Detection> out;
  std::copy_if(d.begin(), d.end(), std::back_inserter(out), [&](const Detection& x) { return x.className == cls; });
  return out;
}

TEST(CocoDetections, ThresholdAndNmsPerClass) {
  const Anchors a = rows({
      {Box{100, 100, 50, 40}, {0.0f, 0.0f, 0.9f}},    // car
      {Box{102, 101, 50, 40}, {0.0f, 0.0f, 0.8f}},    // the same car, IoU ~0.9: suppressed
      {Box{300, 100, 50, 40}, {0.0f, 0.0f, 0.29f}},   // below 0.3
      {Box{100, 100, 50, 40}, {0.6f, 0.0f, 0.0f}},    // a person on the car's box: NMS is per class
      {Box{400, 90, 20, 60}, {0.5f, 0.0f, 0.0f}},     // a lone pedestrian
  });
  const std::vector<Detection> d = cocoDetections(a);
  const auto cars = ofClass(d, "car"), persons = ofClass(d, "person");
  ASSERT_EQ(cars.size(), 1u);
  EXPECT_FLOAT_EQ(static_cast<float>(cars[0].score), 0.9f);
  EXPECT_EQ(cars[0].box, (Box{100, 100, 50, 40}));
  ASSERT_EQ(persons.size(), 2u);
  EXPECT_FLOAT_EQ(static_cast<float>(persons[0].score), 0.6f);  // descending score
  EXPECT_EQ(persons[1].box, (Box{400, 90, 20, 60}));
  EXPECT_TRUE(ofClass(d, "bike").empty());
}

TEST(CocoDetections, RiderOnABicycleIsOneBike) {
  const Anchors a = rows({
      {Box{200, 100, 30, 80}, {0.8f, 0.0f, 0.0f}},   // rider: x 200-230, y 100-180
      {Box{190, 140, 50, 50}, {0.0f, 0.7f, 0.0f}},   // bicycle x 190-240, y 140-190: rider covers 30x40 / 2500 = 0.48
      {Box{500, 100, 30, 80}, {0.9f, 0.0f, 0.0f}},   // pedestrian beside a bicycle
      {Box{528, 150, 50, 40}, {0.0f, 0.6f, 0.0f}},   // its overlap 2x30 / 2000 = 0.03 < 0.3: no rider
  });
  const std::vector<Detection> d = cocoDetections(a);
  const auto bikes = ofClass(d, "bike"), persons = ofClass(d, "person");
  ASSERT_EQ(bikes.size(), 1u);
  EXPECT_EQ(bikes[0].box, (Box{190, 100, 50, 90}));  // union: x 190-240, y 100-190
  EXPECT_FLOAT_EQ(static_cast<float>(bikes[0].score), 0.8f);
  ASSERT_EQ(persons.size(), 1u);  // the rider is no pedestrian; the lone bicycle is nothing
  EXPECT_EQ(persons[0].box, (Box{500, 100, 30, 80}));
  EXPECT_EQ(d.size(), 2u);
  CocoDetectionRule strict;
  strict.minRiderCoverage = 0.5;  // 0.48 no longer rides
  EXPECT_TRUE(ofClass(cocoDetections(a, strict), "bike").empty());
}

}  // namespace
}  // namespace fusedet::fusion
