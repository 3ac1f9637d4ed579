#pragma once
// Learned box refinement (bounding-box regression, as R-CNN-style detectors refine their boxes):
// a detection's box is moved by a linear map of what the detector already knows about it.
//
// Why: car cascades find the cars (training-frame F 0.82-0.84 at IoU 0.5) but place the boxes
// poorly (<= 0.72 at the devkit's IoU 0.7): one window aspect is scanned and a group averages its
// windows. Regressing four edge offsets needs far fewer samples than training a classifier.
// Measured (docs/results "Learned box refinement"): car at IoU 0.7, fitted per fold on its training
// frames, gains +0.07 F on 3 drive-disjoint folds (holds) but ties leave-one-drive-out (-0.004
// [-0.035, +0.027]): off by default (`fusedet experiments --box-fit`), no model holds a fit.
//
// Base box = the detection's box as grouping and the laser extent left it (so no fit = today's
// boxes exactly). Features (boxFeatures(), all relative to the base box, so scale-free):
//   the group box's edges (before the laser extent); the members' edges: mean, spread, min, max
//   (left / top / right / bottom, 16); log(1 + members); the laser-extent edges (laser_extent.h
//   with its general parameters, enabled) and the laser cluster's top/bottom rows
//   (laserRows(), + a flag whether the laser saw the object); log aspect, log height, the box's
//   bottom and its left/right distance to the image border (truncation) as fractions of the image.
// Targets (boxTargets()): dx = (gt centre x - centre x) / w, dy likewise / h, log(gt w / w),
// log(gt h / h); applyTargets() inverts them.
// Fit: ridge regression per target on standardised features with an unpenalised intercept,
// closed form (Eigen, LDLT). Degenerate inputs have a defined outcome: fewer samples than
// `minSamples` -> no fit (identity, `why` says so); a feature constant over the samples gets
// weight 0; collinear features share their weight (the ridge term keeps the system regular;
// lambda must be > 0); a sample with a non-finite value is left out. Predictions are clamped to
// +-maxShift of the box size and a size factor within [1/maxScale, maxScale].

#include <array>
#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "fusedet/core/box.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

using BoxTargets = std::array<double, 4>;  // dx, dy, log dw, log dh

BoxTargets boxTargets(const Box& box, const Box& truth);
Box applyTargets(const Box& box, const BoxTargets& t);

// The detection as the detector formed it: its box after grouping and laser extent (the base),
// the group box before the laser extent, and its group's member windows.
struct GroupedBox {
  Box box;
  Box groupBox;
  std::vector<Box> members;  // empty: no member information (the box itself)
  std::vector<double> memberScores;  // per member: its last-stage sum (group_verifier.h reads them)
};

// The feature vector above (boxFeatureCount() entries, all finite).
std::vector<double> boxFeatures(const GroupedBox& g, const LayerStack& stack);
std::size_t boxFeatureCount();

struct BoxFitParams {
  // lambda and minIou chosen for car on 3 drive-disjoint folds (highest lower bound of the paired
  // F difference at IoU 0.7 among lambda 1-1000, minIou 0.3-0.5; docs/results "Learned box refinement").
  double lambda = 30;          // ridge penalty on standardised features (> 0)
  std::size_t minSamples = 20; // fewer -> no fit
  double minIou = 0.3;         // a training detection's overlap with its label to be a sample
  double maxShift = 0.5;       // |dx|, |dy| clamp (fraction of the box's size)
  double maxScale = 2.0;       // dw, dh clamp (factor)
};

// A fitted refinement; default-constructed = no fit (identity).
struct BoxRegression {
  std::vector<double> mean, scale;               // per feature: standardisation
  std::vector<std::array<double, 4>> weights;    // per feature: the four targets' weights
  std::array<double, 4> intercept{};             // per target
  double maxShift = BoxFitParams{}.maxShift, maxScale = BoxFitParams{}.maxScale;
  double lambda = 0;
  std::size_t samples = 0;
  std::string why;  // when not fitted: why not

  bool fitted() const { return !weights.empty(); }
  BoxTargets predict(std::span<const double> features) const;  // zeros when not fitted
  // The refined box; `g.box` itself when not fitted.
  Box refine(const GroupedBox& g, const LayerStack& stack) const;
};

// Fits on `features[i]` -> `targets[i]`. Throws std::invalid_argument when lambda <= 0 or the
// two differ in number or a row in length.
BoxRegression fitBoxRegression(const std::vector<std::vector<double>>& features, const std::vector<BoxTargets>& targets,
                               const BoxFitParams& params);

}  // namespace fusedet::boosting
