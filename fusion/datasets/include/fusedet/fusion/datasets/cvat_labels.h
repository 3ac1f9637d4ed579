// SPDX-License-Identifier: Apache-2.0
#pragma once
// CVAT's "CVAT for images 1.1" XML for labels in and out of a data set: <annotations> with a
// <version>1.1</version>, a <meta><task> naming the labels, and per image <image id name width
// height> holding <box label occluded xtl ytl xbr ybr> (corners in pixels). Our occlusion level,
// truncation and ignore flag travel as box attributes "occlusion", "truncation", "ignore"
// (declared in the meta, so CVAT shows them); occluded = occlusion level >= 1. A teacher's box is
// source="auto"; a box a person drew or corrected (manual, semi-auto) reads back as human.
// Shapes other than boxes (polygons, points, ...) carry no box: the reader counts and skips them.

#include <string>
#include <vector>

#include "fusedet/fusion/datasets/label_exchange.h"

namespace fusedet::fusion {

std::string cvatFromImages(const std::vector<ExchangeImage>& images, const std::string& taskName);

struct CvatLabels {
  std::vector<ExchangeImage> images;
  std::size_t skippedShapes = 0;  // polygons, polylines, points, ellipses, masks, cuboids, skeletons
};
// Throws std::runtime_error naming `file`, the image and the attribute at fault.
CvatLabels imagesFromCvat(const std::string& xml, const LabelClassTable& table, const std::string& file);

}  // namespace fusedet::fusion
