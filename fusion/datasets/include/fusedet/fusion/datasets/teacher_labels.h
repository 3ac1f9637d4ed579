// SPDX-License-Identifier: Apache-2.0
#pragma once
// A pretrained COCO detector as a labelling teacher (fusedet autolabel): its detections of the
// project's classes on a stack's camera image (fusedet/fusion/neural: one runner and decoder for
// the peer, the neural layers and this) become labels with origin "teacher":
//  - score >= minScore: a label of its class;
//  - uncertainScore <= score < minScore: an ignore region (neither taught as object nor as
//    background);
//  - laser veto: a box where depth is expected but none is measured is dropped. Expected: at least
//    expectedDepthShare of the distance layer's cells in the ring around the box (the box grown by
//    half its size on each side, minus the box) are measured; none measured: fewer than
//    minDepthShareInside of the cells inside the box. A real object in the laser's field of view
//    returns light; a box on the sky, a reflection or a picture of something far beyond range
//    does not. Boxes outside the laser's field of view (ring mostly unmeasured) are kept.
// Merging with what an item has: earlier teacher labels are replaced, human labels kept (unless
// replaceHuman), and a teacher box overlapping a human one (IoU >= humanOverlapIou) is left out.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/core/label.h"
#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/neural/coco_detections.h"
#include "fusedet/fusion/neural/network.h"

namespace fusedet::fusion {

struct TeacherRule {
  std::vector<std::string> classes = {"person", "car", "bike"};
  double minScore = 0.5;
  double uncertainScore = 0.25;
  CocoDetectionRule detection;  // NMS IoU and rider coverage; its minScore is uncertainScore
  bool laserVeto = true;
  double expectedDepthShare = 0.5;
  double minDepthShareInside = 0.02;
  bool replaceHuman = false;
  double humanOverlapIou = 0.5;
};

struct TeacherCounts {
  std::size_t labels = 0;          // confident boxes kept
  std::size_t ignoreRegions = 0;   // uncertain boxes
  std::size_t vetoed = 0;          // dropped by the laser veto
  std::size_t underHuman = 0;      // left out: a human label is there
  TeacherCounts& operator+=(const TeacherCounts& o);
};

// Share of measured cells of the stack's distance layer inside `box` and in the ring around it
// (reference pixels); {-1, -1} when the stack has no distance layer.
struct DepthCoverage {
  double inside = -1, around = -1;
};
DepthCoverage depthCoverage(const LayerStack& stack, const Box& box);

// Teacher labels from a detector's detections (reference pixels, any score) on `stack`.
Labels teacherLabels(const std::vector<Detection>& detections, const LayerStack& stack, const TeacherRule& rule,
                     TeacherCounts& counts);

// The network on the stack's camera image, decoded into detections (cocoDetections with the
// rule's uncertain score) and turned into teacher labels.
Labels teachStack(Network& network, const LayerStack& stack, const TeacherRule& rule, TeacherCounts& counts);

// An item's labels after teaching: see the header comment.
Labels mergeTeacherLabels(const Labels& existing, const Labels& taught, const TeacherRule& rule, TeacherCounts& counts);

}  // namespace fusedet::fusion
