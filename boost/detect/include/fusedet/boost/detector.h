// SPDX-License-Identifier: Apache-2.0
#pragma once
// Detector: runs one Cascade over every window of a LayerStack (positions x scales) with early
// exit, returning raw hits; grouping.h turns hits into Detections.
//
// Our models scan the stack directly: window sizes grow from the minimum size by the scale
// factor at the model's aspect ratio, features are mapped to each layer's grid per scale once
// (offsets precomputed, OpenCV's OptFeature idea). Imported OpenCV models scan OpenCV's image
// pyramid of their one 8-bit layer instead (opencv_cascade.h has the details), so that their
// window decisions equal cv::CascadeClassifier's.
//
// Two scanners with the same decisions (tested): scan(LayerStack) builds its integrals in one pass
// into grids whose layers' rows are interleaved and evaluates four windows per step with AVX2
// (multi_detector.h runs several models this way on one pass); scan(IntegralStack) is the
// one-window-at-a-time path on per-layer tables that training uses and tests compare against.
// Threads: bands of window columns over TBB tasks; hits are merged in (scale, row, column) order,
// so the output is identical for any thread count.

#include <cstddef>
#include <memory>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/integral_stack.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

struct ScanParams {
  double scaleFactor = 1.1;      // > 1
  int minWidth = 0, minHeight = 0;  // reference pixels; 0 = the model's base window
  int maxWidth = 0, maxHeight = 0;  // 0 = the whole stack
  // Position step of our models in base-window pixels, scaled with the window (minimum 1 pixel).
  // OpenCV models use OpenCV's rule (2 pixels of the scaled image below scale 2, else 1).
  double step = 2;
  int threads = 0;  // 0 = all cores (TBB default), 1 = the calling thread only
};

struct WindowResult {
  bool accepted = false;
  double score = 0;      // sum of the last stage evaluated
  int stagesPassed = 0;  // == stage count when accepted
};

struct RawHit {
  Box box;           // reference pixels
  double score = 0;  // sum of the last stage
  int scale = 0;     // index of the scale the window was found at
};

struct ScanStats {
  std::size_t windows = 0;   // windows evaluated
  std::size_t stumps = 0;    // weak classifiers of the stages the windows reached (the vector scanners may decide a stage before its last)
  std::size_t scales = 0;
};

// One cascade on one window of reference pixels (our models; the slow, obvious path that the
// scanner must agree with). Throws std::invalid_argument for an OpenCV model (use the pyramid).
WindowResult evaluateWindow(const Cascade& cascade, const IntegralStack& integrals,
                            const Box& window);

// Layer names a cascade needs from a stack, and the integrals for them.
IntegralStack integrateFor(const Cascade& cascade, const LayerStack& stack);

// The widest vector path the one-pass scanner may use for our models: 8 windows per step
// (AVX-512), 4 (AVX2) or 1 (scalar); the CPU decides below that. Process-wide; for tests and
// benchmarks that compare the paths (all decide the same). setVectorScanEnabled(false)
// (opencv_cascade.h) switches every vector path off.
void setVectorLanesLimit(int lanes);

// The vector paths decide a stump with products instead of the feature's divisions wherever the
// product form is provably on the same side of the threshold, and only the few windows too close
// to call with the divisions (window_scanner.h). false sends every window through that exact
// fallback. Process-wide; for tests that compare the two (they decide the same).
void setQuickStumpDecisions(bool enabled);

class Detector {
 public:
  // Validates the cascade (throws std::invalid_argument naming its source and the problem).
  explicit Detector(Cascade cascade);
  ~Detector();
  Detector(Detector&&) noexcept;
  Detector& operator=(Detector&&) noexcept;

  const Cascade& cascade() const { return cascade_; }

  // Raw hits of every window; stats (optional) counts the work done.
  std::vector<RawHit> scan(const LayerStack& stack, const ScanParams& params,
                           ScanStats* stats = nullptr) const;
  // Same on integrals built by the caller (our models only; the scalar reference scanner).
  std::vector<RawHit> scan(const IntegralStack& integrals, const ScanParams& params,
                           ScanStats* stats = nullptr) const;

 private:
  Cascade cascade_;
};

}  // namespace fusedet::boosting
