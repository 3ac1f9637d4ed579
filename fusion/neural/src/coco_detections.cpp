// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/coco_detections.h"

#include <algorithm>
#include <opencv2/dnn.hpp>
#include <stdexcept>

namespace fusedet::fusion {
namespace {

struct Scored {
  Box box;
  double score = 0;
};

// Rows of one class above the threshold, kept by NMS, highest score first.
std::vector<Scored> classDetections(const Anchors& a, int classId, const CocoDetectionRule& rule) {
  if (classId >= a.classes())
    throw std::invalid_argument("COCO detections: the network has " + std::to_string(a.classes()) +
                                " classes, class " + std::to_string(classId) + " is missing");
  std::vector<cv::Rect2d> boxes;
  std::vector<float> scores;
  for (std::size_t r = 0; r < a.size(); ++r) {
    const float s = a.scores.at<float>(static_cast<int>(r), classId);
    if (s < rule.minScore) continue;
    const Box& b = a.boxes[r];
    boxes.emplace_back(b.x, b.y, b.w, b.h);
    scores.push_back(s);
  }
  std::vector<int> kept;
  cv::dnn::NMSBoxes(boxes, scores, static_cast<float>(rule.minScore), static_cast<float>(rule.nmsIou), kept);
  std::vector<Scored> out;
  for (int k : kept) out.push_back({Box{boxes[k].x, boxes[k].y, boxes[k].width, boxes[k].height}, scores[k]});
  std::stable_sort(out.begin(), out.end(), [](const Scored& x, const Scored& y) { return x.score > y.score; });
  return out;
}

Detection detection(const char* cls, const Box& box, double score) {
  Detection d;
  d.className = cls;
  d.box = box;
  d.score = score;
  return d;
}

Box unionBox(const Box& a, const Box& b) {
  const double x = std::min(a.x, b.x), y = std::min(a.y, b.y);
  return Box{x, y, std::max(a.right(), b.right()) - x, std::max(a.bottom(), b.bottom()) - y};
}

}  // namespace

std::vector<Detection> cocoDetections(const Anchors& anchors, const CocoDetectionRule& rule) {
  const std::vector<Scored> persons = classDetections(anchors, coco::kPerson, rule);
  const std::vector<Scored> bicycles = classDetections(anchors, coco::kBicycle, rule);
  const std::vector<Scored> cars = classDetections(anchors, coco::kCar, rule);

  std::vector<Detection> out;
  for (const Scored& c : cars) out.push_back(detection("car", c.box, c.score));
  // Each bicycle to the person covering most of it (persons are in descending score order, so a
  // tie keeps the earlier, higher-scoring one).
  std::vector<int> bicycleOf(persons.size(), -1);
  for (std::size_t b = 0; b < bicycles.size(); ++b) {
    int best = -1;
    double bestCover = rule.minRiderCoverage;
    for (std::size_t p = 0; p < persons.size(); ++p) {
      const double cover = bicycles[b].box.area() > 0
                               ? intersectionArea(bicycles[b].box, persons[p].box) / bicycles[b].box.area()
                               : 0.0;
      if (cover >= bestCover && (best < 0 || cover > bestCover)) {
        best = static_cast<int>(p);
        bestCover = cover;
      }
    }
    if (best >= 0 && bicycleOf[static_cast<std::size_t>(best)] < 0) bicycleOf[static_cast<std::size_t>(best)] = static_cast<int>(b);
  }
  for (std::size_t p = 0; p < persons.size(); ++p)
    if (bicycleOf[p] >= 0)
      out.push_back(detection("bike", unionBox(persons[p].box, bicycles[static_cast<std::size_t>(bicycleOf[p])].box),
                              persons[p].score));
  for (std::size_t p = 0; p < persons.size(); ++p)
    if (bicycleOf[p] < 0) out.push_back(detection("person", persons[p].box, persons[p].score));
  return out;
}

}  // namespace fusedet::fusion
