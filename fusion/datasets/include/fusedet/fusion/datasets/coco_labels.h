// SPDX-License-Identifier: Apache-2.0
#pragma once
// COCO object-detection JSON (the "instances" layout: images, annotations, categories) for labels in
// and out of a data set. Field rules as COCO publishes them: integer ids, unique per list; an
// annotation's image_id and category_id name an image and a category; bbox = [x, y, width, height]
// in pixels from the top-left corner; area = the box's area here (no masks); iscrowd 1 marks a
// region that is neither hit nor miss, which is our ignore region. person, bicycle and car keep
// COCO's own category ids (1, 2, 3), so files line up with COCO-trained tools.
// Occlusion and truncation, which COCO has no field for, travel as extra annotation keys
// "occlusion" and "truncation", and who drew the box as "origin" (human | teacher) (COCO readers
// skip keys they do not know).

#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/fusion/datasets/label_exchange.h"

namespace fusedet::fusion {

nlohmann::json cocoFromImages(const std::vector<ExchangeImage>& images);

// Throws std::runtime_error naming `file` and the offending field (e.g. "annotations[3].bbox").
std::vector<ExchangeImage> imagesFromCoco(const nlohmann::json& coco, const LabelClassTable& table,
                                          const std::string& file);

// The COCO name of a project class: "bike" -> "bicycle"; person and car as they are.
std::string cocoClassName(const std::string& projectClass);

// Detections as a COCO results file ([{"image_id", "category_id", "bbox", "score"}], what COCO's
// evaluation reads beside the labels): image ids as cocoFromImages gives them to the data set's
// items (1 + the item's place in the manifest, `manifestIds`), category ids of COCO (person 1,
// bicycle 2, car 3). Throws std::invalid_argument for an item id not in the manifest or a class
// without a COCO category.
nlohmann::json cocoResults(const std::vector<std::string>& manifestIds,
                           const std::vector<std::pair<std::string, std::vector<Detection>>>& detectionsPerItem);

}  // namespace fusedet::fusion
