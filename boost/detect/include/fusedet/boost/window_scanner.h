// SPDX-License-Identifier: Apache-2.0
#pragma once
// The scanner of our models (internal to boost/; Detector and MultiDetector are the entry points).
//
// Several cascades scan one stack together: one IntegralGrids pass serves them all, and the work
// (cascade x scale x band of window columns, every row) is shared by the threads in one index
// space. Within a band, windows are evaluated breadth-first: stage 0 on a chunk of rows, then each
// later stage on the compacted list of the windows that passed the one before, so that vector
// lanes (eight windows per step with AVX-512, four with AVX2 or NEON: vector_path.h; corners loaded whole
// from the grids where neighbouring windows' origins are regular, else one lane at a time) stay busy although most windows leave after a stage or two. Per window the arithmetic is that of featureValue() and
// evaluateWindow(), in the same order and precision (division, no FMA): the decisions and scores
// are those of the one-window reference path, bit for bit (tested).

#include <cstddef>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/integral_grids.h"

namespace fusedet::boosting {

// Window sizes and positions of one scale (reference pixels): sizes grow from the minimum size by
// the scale factor at the model's aspect ratio, the position step grows with them.
struct ScaleWindows {
  int winW = 0, winH = 0, step = 1;
  std::vector<int> xs, ys;
};
std::vector<ScaleWindows> windowScales(const Cascade& c, int refWidth, int refHeight, const ScanParams& p);

// Layers the cascade reads (hue_distance with the cascade's reference hue).
std::vector<LayerRequest> layerRequests(const Cascade& c);

// Raw hits of each cascade (our models only) on integrals built for all of them, each in
// (scale, row, column) order; stats[i] (optional, one per cascade) counts the work.
std::vector<std::vector<RawHit>> scanCascades(const std::vector<const Cascade*>& cascades,
                                              const IntegralGrids& grids, const ScanParams& params,
                                              std::vector<ScanStats>* stats);

}  // namespace fusedet::boosting
