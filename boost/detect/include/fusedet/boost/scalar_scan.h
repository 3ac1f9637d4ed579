// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one-window scalar scan of our models on per-layer integral tables (internal to boost/):
// per scale, every stump's rectangle corners as offsets from the window's origin in its layer's
// table (OpenCV's OptFeature idea), and the evaluation of one window with early exit. Used by
// Detector::scan(IntegralStack) (the reference scanner) and by training's negative mining
// (negative_miner.h), which evaluates only the stages a window has not yet passed.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/integral_stack.h"

namespace fusedet::boosting {

// One stump with its feature laid out for one scale: rectangle corners as offsets from the
// window's origin in its layer's integral (OpenCV's OptFeature idea), flat for the hot loop.
// Branch-free form of FeatureLayout (stump types mix unpredictably): black = rect 0 + rect 1
// (rect 1 is an empty rectangle, sum exactly 0, unless the type has two black parts), white =
// rect 2 - rest * black with rest = 1 when rect 2 is the outer rectangle, else 0. Same values as
// featureValue() (adding or subtracting an exact zero changes nothing but the sign of a zero).
struct ScaledStump {
  int layer = 0;
  std::array<std::array<std::int32_t, 4>, 3> ofs{};  // (x0,y0) (x1,y0) (x0,y1) (x1,y1)
  double rest = 0;
  double blackArea = 1, whiteArea = 1;
  float threshold = 0;
  std::array<double, 2> leaf{};  // left, right: indexed, not branched on
};

struct ScaledStage {
  std::size_t begin = 0, end = 0;  // range in the stump array
  double threshold = 0;
};

struct ScalePlan {
  int winW = 0, winH = 0, step = 1;
  std::vector<int> xs, ys;                       // window positions (reference pixels)
  std::vector<std::vector<std::ptrdiff_t>> colOfs, rowOfs;  // per layer, per position
  std::vector<ScaledStump> stumps;
  std::vector<ScaledStage> stages;
};

// Plans of every scale windowScales() gives for `c` on `in` (our models only).
std::vector<ScalePlan> planScales(const Cascade& c, const IntegralStack& in, const ScanParams& p);

// The hot loop: same arithmetic, in the same order, as featureValue() + evaluateWindow().
inline WindowResult runWindow(const ScalePlan& sp, const double* const* base, std::size_t& stumps) {
  WindowResult r;
  for (const ScaledStage& st : sp.stages) {
    double sum = 0;
    for (std::size_t k = st.begin; k < st.end; ++k) {
      const ScaledStump& z = sp.stumps[k];
      const double* p = base[z.layer];
      auto rs = [p](const std::array<std::int32_t, 4>& o) { return p[o[3]] - p[o[1]] - p[o[2]] + p[o[0]]; };
      const double black = rs(z.ofs[0]) + rs(z.ofs[1]);
      const double white = rs(z.ofs[2]) - z.rest * black;
      const auto v = static_cast<float>(black / z.blackArea - white / z.whiteArea);
      sum += z.leaf[static_cast<std::size_t>(!(v < z.threshold))];
    }
    stumps += st.end - st.begin;
    r.score = sum;
    if (sum < st.threshold) return r;
    ++r.stagesPassed;
  }
  r.accepted = true;
  return r;
}

}  // namespace fusedet::boosting
