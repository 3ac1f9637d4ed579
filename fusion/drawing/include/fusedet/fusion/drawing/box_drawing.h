// SPDX-License-Identifier: Apache-2.0
#pragma once
// Labels and detections drawn on an 8-bit BGR image: the one box-drawing rule of the project
// (`fusedet show`'s mosaics, `fusedet detect --draw`). Labels: green (car/person/bike/...),
// orange ("van"), grey dashed ignore regions; labels a teacher network drew (origin "teacher",
// fusedet autolabel): cyan, thin, "(teacher)" after the class, its ignore regions cyan dashed;
// detections: red with class and score.

#include <opencv2/core/mat.hpp>
#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/core/label.h"

namespace fusedet::fusion {

// Boxes are in the image's reference pixels times `scale`.
void drawBoxes(cv::Mat& image, double scale, const Labels& labels, const std::vector<Detection>& detections);

}  // namespace fusedet::fusion
