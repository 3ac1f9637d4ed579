// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scanning of imported OpenCV Haar cascades the way cv::CascadeClassifier::detectMultiScale does
// (OpenCV 4 cascadedetect): the 8-bit layer is resized per scale (INTER_LINEAR_EXACT), integrated
// (sum, wrapping 32-bit squared sum, tilted sum), windows of the base size are visited with a
// step of 2 below scale 2 and 1 above, skipping the next position after a window fails the first
// stage; each window is normalised by its standard deviation over the inner (w-2)x(h-2) area and
// rejected when that is at most 10 grey levels; feature values and stage sums use OpenCV's float
// and double arithmetic in the same order. Internal to boost/ (Detector::scan is the entry point).

#include <cstdint>
#include <vector>

#include <opencv2/core/mat.hpp>

#include "fusedet/boost/detector.h"

namespace fusedet::boosting {

std::vector<RawHit> scanOpenCvPyramid(const Cascade& cascade, const LayerStack& stack,
                                      const ScanParams& params, ScanStats* stats);

// The three integrals of one 8-bit image as OpenCV's cascade uses them, (w+1) x (h+1) each.
struct CvIntegrals {
  int width = 0, height = 0;  // image size
  std::vector<std::int32_t> sum;
  std::vector<std::uint32_t> sqsum;   // modulo 2^32, like OpenCV's CV_32S squared sum
  std::vector<std::int32_t> tilted;   // empty unless requested
  std::ptrdiff_t stride() const { return width + 1; }
};
void integrateCv(const cv::Mat& gray, bool tilted, CvIntegrals& out);

}  // namespace fusedet::boosting
