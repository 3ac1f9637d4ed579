// SPDX-License-Identifier: Apache-2.0
#pragma once
// A COCO detector's anchor rows as detections of the project's classes (the CNN alone as a peer,
// camera only). COCO has no cyclist: a person riding a bicycle is the usual stand-in.
//  1. per COCO class (person 0, bicycle 1, car 2): rows with score >= minScore, then NMS at
//     IoU nmsIou (cv::dnn::NMSBoxes, highest score first) - ../shared/models/SOURCE.md's rule;
//  2. car = COCO car;
//  3. bike = a person whose box covers at least minRiderCoverage of a bicycle's box (intersection
//     / bicycle area; each bicycle goes to the person covering most of it, ties to the higher
//     score; a person rides at most one bicycle, the first by score): the union of both boxes,
//     with the person's score (KITTI labels the rider with the
//     bike, and it is the person the network is surest of);
//  4. person = every other person. A bicycle without a rider is no detection (KITTI labels only
//     ridden bicycles).
// Other COCO classes (truck, bus, motorcycle...) are not used.

#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/fusion/neural/anchors.h"

namespace fusedet::fusion {

namespace coco {
inline constexpr int kPerson = 0;
inline constexpr int kBicycle = 1;
inline constexpr int kCar = 2;
}  // namespace coco

struct CocoDetectionRule {
  double minScore = 0.3;  // SOURCE.md's measured operating point
  double nmsIou = 0.45;
  double minRiderCoverage = 0.3;
};

// Detections of "car", "person" and "bike" in the anchors' image pixels (Detection::box; unitBox,
// stamp and stack id left for the caller), each class by descending score.
std::vector<Detection> cocoDetections(const Anchors& anchors, const CocoDetectionRule& rule = {});

}  // namespace fusedet::fusion
