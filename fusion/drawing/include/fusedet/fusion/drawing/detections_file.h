// SPDX-License-Identifier: Apache-2.0
#pragma once
// The detections file `fusedet show --detections` reads:
//   {"detections": [{"class": "car", "score": 3.2, "x": 10, "y": 20, "w": 40, "h": 30}, ...]}
// Boxes in the stack's reference pixels (x, y = top-left corner). Other keys are ignored.

#include <filesystem>
#include <string>
#include <vector>

#include "fusedet/core/detection.h"

namespace fusedet::fusion {

// Strict: throws std::runtime_error naming the file (or `what`) and the problem, with the index
// of a bad entry (missing or mistyped key, non-finite number, negative size).
std::vector<Detection> parseDetectionsJson(const std::string& text, const std::string& what = "detections");
std::vector<Detection> readDetectionsFile(const std::filesystem::path& file);

}  // namespace fusedet::fusion
