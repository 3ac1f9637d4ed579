// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/teacher_labels.h"

#include <algorithm>
#include <cmath>
#include <opencv2/core.hpp>
#include <stdexcept>

#include "fusedet/fusion/camera_layers.h"

namespace fusedet::fusion {

TeacherCounts& TeacherCounts::operator+=(const TeacherCounts& o) {
  labels += o.labels;
  ignoreRegions += o.ignoreRegions;
  vetoed += o.vetoed;
  underHuman += o.underHuman;
  return *this;
}

namespace {

// Measured cells and all cells of the layer inside a rectangle of layer pixels (clipped).
std::pair<double, double> countMeasured(const Layer& layer, const cv::Rect& r) {
  const cv::Rect clipped = r & cv::Rect(0, 0, layer.width(), layer.height());
  if (clipped.area() <= 0) return {0, 0};
  const double measured = layer.hasMask() ? cv::countNonZero(layer.valid(clipped)) : clipped.area();
  return {measured, static_cast<double>(clipped.area())};
}

cv::Rect layerRect(const LayerStack& stack, const Layer& layer, const Box& box) {
  const Box b = LayerStack::toLayerPixels(layer, stack.toUnit(box));
  const int x0 = static_cast<int>(std::floor(b.x)), y0 = static_cast<int>(std::floor(b.y));
  const int x1 = static_cast<int>(std::ceil(b.x + b.w)), y1 = static_cast<int>(std::ceil(b.y + b.h));
  return {x0, y0, std::max(0, x1 - x0), std::max(0, y1 - y0)};
}

}  // namespace

DepthCoverage depthCoverage(const LayerStack& stack, const Box& box) {
  const Layer* distance = stack.find("distance");
  if (!distance) return {};
  const auto [inMeasured, inCells] = countMeasured(*distance, layerRect(stack, *distance, box));
  const Box grown{box.x - box.w / 2, box.y - box.h / 2, box.w * 2, box.h * 2};
  const auto [allMeasured, allCells] = countMeasured(*distance, layerRect(stack, *distance, grown));
  DepthCoverage c;
  c.inside = inCells > 0 ? inMeasured / inCells : 0;
  c.around = allCells - inCells > 0 ? (allMeasured - inMeasured) / (allCells - inCells) : 0;
  return c;
}

Labels teacherLabels(const std::vector<Detection>& detections, const LayerStack& stack, const TeacherRule& rule,
                     TeacherCounts& counts) {
  Labels labels;
  for (const Detection& d : detections) {
    if (std::find(rule.classes.begin(), rule.classes.end(), d.className) == rule.classes.end()) continue;
    if (d.score < rule.uncertainScore) continue;
    if (rule.laserVeto) {
      const DepthCoverage c = depthCoverage(stack, d.box);
      if (c.around >= rule.expectedDepthShare && c.inside < rule.minDepthShareInside) {
        ++counts.vetoed;
        continue;
      }
    }
    Label l;
    l.className = d.className;
    l.sourceClass = d.className;
    l.box = d.box;
    l.origin = "teacher";
    l.ignore = d.score < rule.minScore;
    ++(l.ignore ? counts.ignoreRegions : counts.labels);
    labels.push_back(std::move(l));
  }
  return labels;
}

Labels teachStack(Network& network, const LayerStack& stack, const TeacherRule& rule, TeacherCounts& counts) {
  const cv::Mat bgr = cameraImage(stack);
  CocoDetectionRule detection = rule.detection;
  detection.minScore = rule.uncertainScore;
  std::vector<Detection> detections = cocoDetections(network.run(bgr), detection);
  // The camera layers may be smaller than the reference grid: boxes go to reference pixels.
  const double sx = static_cast<double>(stack.width()) / bgr.cols, sy = static_cast<double>(stack.height()) / bgr.rows;
  for (Detection& d : detections) d.box = Box{d.box.x * sx, d.box.y * sy, d.box.w * sx, d.box.h * sy};
  return teacherLabels(detections, stack, rule, counts);
}

Labels mergeTeacherLabels(const Labels& existing, const Labels& taught, const TeacherRule& rule, TeacherCounts& counts) {
  Labels out;
  for (const Label& l : existing)
    if (l.origin == "human" && !rule.replaceHuman) out.push_back(l);
  const std::size_t human = out.size();
  for (const Label& t : taught) {
    const bool covered = std::any_of(out.begin(), out.begin() + static_cast<std::ptrdiff_t>(human),
                                     [&](const Label& h) { return iou(h.box, t.box) >= rule.humanOverlapIou; });
    if (covered) {
      ++counts.underHuman;
      --(t.ignore ? counts.ignoreRegions : counts.labels);
      continue;
    }
    out.push_back(t);
  }
  return out;
}

}  // namespace fusedet::fusion
