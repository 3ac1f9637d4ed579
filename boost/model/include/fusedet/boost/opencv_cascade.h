// SPDX-License-Identifier: Apache-2.0
#pragma once
// Import of OpenCV Haar cascades as Debian's opencv-data ships them
// (/usr/share/opencv4/haarcascades): the current format (<cascade> with stageType BOOST,
// featureType HAAR, stages/weakClassifiers/internalNodes/leafValues, features/rects/tilted) and
// the old one (type_id "opencv-haar-classifier": <size>, stages/trees with inline features),
// which OpenCV converts to the same model on load.
//
// The result is a Cascade with Normalization::kOpenCvVariance, one layer (default "intensity")
// and OpenCV's load-time conventions applied, so that decisions match cv::CascadeClassifier bit
// for bit: thresholds and leaves rounded to float, leaves below 1e-5 in magnitude set to 0, stage
// thresholds lowered by 1e-5 (OpenCV's THRESHOLD_EPS).
//
// Weak classifiers that split once become Stumps; cascades with deeper trees (alt2, *_2splits,
// eye_tree_eyeglasses) keep them as Trees (cascade.h) and run on the one-window-at-a-time path.
// LBP/HOG cascades are rejected with a clear message.

#include <filesystem>
#include <string>
#include <string_view>

#include "fusedet/boost/cascade.h"

namespace fusedet::boosting {

// Throws std::runtime_error "FILE: line N: problem" for unreadable, malformed or inconsistent
// files (truncated XML, wrong counts, non-finite numbers, unknown feature or stage types,
// indices or rectangles out of range).
Cascade loadOpenCvCascade(const std::filesystem::path& file, const std::string& layer = "intensity");
// Same from text; `source` names it in messages.
Cascade parseOpenCvCascade(std::string_view xml, const std::string& source,
                           const std::string& layer = "intensity");

// Scanning uses an AVX2 path (eight windows per step, the same per-window arithmetic, so the same
// decisions) when the CPU has AVX2 (and FUSEDET_SIMD allows it: fusedet/boost/vector_path.h).
// Tests and benchmarks switch every vector path off (process-wide, this scanner's and the
// one-pass scanner's) to compare with the one-window-at-a-time reference path.
void setVectorScanEnabled(bool enabled);

}  // namespace fusedet::boosting
