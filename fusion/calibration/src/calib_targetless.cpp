// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/calib_targetless.h"

#include <cmath>
#include <stdexcept>

#include "alignment_cost.h"
#include "jackknife.h"
#include "fusedet/fusion/calibration/nelder_mead.h"

namespace fusedet::fusion {
namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr double kTranslationUnit = 0.1;  // [m] the optimiser moves translation in decimetres
constexpr double kTolerance = 0.005;      // [deg] and [dm]: 0.005 deg, 0.5 mm

// x = (rotation vector [deg], translation [dm]) applied in the camera frame after `base`.
Eigen::Isometry3d applyDelta(const Eigen::Isometry3d& base, const Eigen::VectorXd& x) {
  const Eigen::Vector3d w = x.head<3>() * kDeg;
  Eigen::Isometry3d delta = Eigen::Isometry3d::Identity();
  if (w.norm() > 0) delta.linear() = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  delta.translation() = x.tail<3>() * kTranslationUnit;
  return delta * base;
}

// What the optimiser maximises: one measure, or both, each relative to its value at `start`
// so that neither dominates by its units.
struct Objective {
  AlignmentMeasure measure;
  double miWeight = 1, edgeWeight = 1;

  Objective(AlignmentMeasure m, const AlignmentScore& start) : measure(m) {
    if (m == AlignmentMeasure::kBoth) {
      miWeight = 1.0 / std::max(start.mutualInformation, 1e-6);
      edgeWeight = 1.0 / std::max(start.edgeAlignment, 1e-6);
    }
  }
  double value(const AlignmentScore& s) const {
    switch (measure) {
      case AlignmentMeasure::kMutualInformation: return s.mutualInformation;
      case AlignmentMeasure::kEdges: return s.edgeAlignment;
      case AlignmentMeasure::kBoth: break;
    }
    return miWeight * s.mutualInformation + edgeWeight * s.edgeAlignment;
  }
};

struct Search {
  Eigen::VectorXd x;
  double value = 0;  // of the minimised (negated) objective
  int evaluations = 0;
};

// Nelder-Mead from x0, restarted from its best point while a restart still improves.
Search searchFrom(const std::function<double(const Eigen::VectorXd&)>& f, const Eigen::VectorXd& x0,
                  const Eigen::VectorXd& step, int restarts, int maxEvaluations) {
  NelderMeadOptions nm;
  nm.maxEvaluations = maxEvaluations;
  nm.xTolerance = kTolerance;
  nm.fTolerance = 1e-12;
  Search best{x0, f(x0), 1};
  for (int r = 0; r <= restarts; ++r) {
    const NelderMeadResult res = minimiseNelderMead(f, best.x, step, nm);
    best.evaluations += res.evaluations;
    const bool improved = res.value < best.value - 1e-9 * std::abs(best.value);
    if (res.value < best.value) {
      best.x = res.x;
      best.value = res.value;
    }
    if (!improved) break;
  }
  return best;
}

}  // namespace

AlignmentMeasure parseAlignmentMeasure(const std::string& name) {
  if (name == "mi") return AlignmentMeasure::kMutualInformation;
  if (name == "edges") return AlignmentMeasure::kEdges;
  if (name == "both") return AlignmentMeasure::kBoth;
  throw std::invalid_argument("unknown alignment measure '" + name + "' (expected mi, edges or both)");
}

const char* alignmentMeasureName(AlignmentMeasure m) {
  switch (m) {
    case AlignmentMeasure::kMutualInformation: return "mi";
    case AlignmentMeasure::kEdges: return "edges";
    case AlignmentMeasure::kBoth: return "both";
  }
  return "?";
}

double rotationErrorDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle() / kDeg;
}

double translationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return (a.translation() - b.translation()).norm();
}

namespace {

void checkFrames(const std::vector<CalibFrame>& frames, const TargetlessOptions& options) {
  if (frames.empty()) throw std::invalid_argument("targetless calibration: no frames");
  if (options.pyramidLevels < 1 || options.pyramidLevels > 6)
    throw std::invalid_argument("targetless calibration: pyramid levels must be 1..6");
  for (const CalibFrame& f : frames)
    if (f.image.cols < (8 << options.pyramidLevels) || f.image.rows < (8 << options.pyramidLevels))
      throw std::invalid_argument("targetless calibration: image of frame '" + f.name + "' is too small for " +
                                  std::to_string(options.pyramidLevels) + " pyramid levels");
}

std::vector<std::vector<detail::LevelImage>> pyramids(const std::vector<CalibFrame>& frames, int levels, double edgeDecay) {
  std::vector<std::vector<detail::LevelImage>> out;
  out.reserve(frames.size());
  for (const CalibFrame& f : frames) out.push_back(detail::prepareLevelImages(f.image, levels, edgeDecay));
  return out;
}

}  // namespace

std::vector<AlignmentScore> scoreAlignments(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K,
                                            const Eigen::Isometry3d& reference,
                                            const std::vector<Eigen::Isometry3d>& candidates,
                                            const TargetlessOptions& options) {
  checkFrames(frames, options);
  const auto laser = detail::prepareLaserSamples(frames, K, reference, options);
  const auto images = pyramids(frames, 1, options.edgeDecay);
  const detail::AlignmentCost cost(laser, images, K, 0);
  std::vector<AlignmentScore> out;
  for (const Eigen::Isometry3d& T : candidates) out.push_back(cost.score(T));
  return out;
}

TargetlessResult calibrateTargetless(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K,
                                     const Eigen::Isometry3d& init, const TargetlessOptions& options) {
  checkFrames(frames, options);
  const auto laser = detail::prepareLaserSamples(frames, K, init, options);
  const auto images = pyramids(frames, options.pyramidLevels, options.edgeDecay);
  TargetlessResult result;
  Eigen::Isometry3d current = init;
  auto outside = [&](const Eigen::Isometry3d& T) {
    return rotationErrorDeg(T, init) > options.maxRotationDeg || translationError(T, init) > options.maxTranslation;
  };
  Eigen::VectorXd step(6);
  for (int level = options.pyramidLevels - 1; level >= 0; --level) {
    const detail::AlignmentCost cost(laser, images, K, level);
    const Objective objective(options.measure, cost.score(current, {}, options.measure));
    auto f = [&](const Eigen::VectorXd& x) {
      const Eigen::Isometry3d T = applyDelta(current, x);
      if (outside(T)) return 1e9;
      return -objective.value(cost.score(T, {}, options.measure));
    };
    const double shrink = std::ldexp(1.0, level - (options.pyramidLevels - 1));
    step << Eigen::Vector3d::Constant(options.rotationStepDeg * shrink),
        Eigen::Vector3d::Constant(options.translationStep * shrink / kTranslationUnit);
    const Search s = searchFrom(f, Eigen::VectorXd::Zero(6), step, options.restartsPerLevel, options.maxEvaluationsPerRun);
    result.evaluations += s.evaluations;
    current = applyDelta(current, s.x);
  }
  result.laserToCamera = current;
  const detail::AlignmentCost full(laser, images, K, 0);
  result.before = full.score(init);
  result.after = full.score(current);
  if (!options.estimateUncertainty || frames.size() < 3) return result;

  // Jackknife: re-optimise at full resolution with each frame left out, starting at the result.
  const Objective objective(options.measure, result.after);
  std::vector<Eigen::Isometry3d> loo;
  for (std::size_t leave = 0; leave < frames.size(); ++leave) {
    std::vector<bool> skip(frames.size(), false);
    skip[leave] = true;
    auto f = [&](const Eigen::VectorXd& x) {
      const Eigen::Isometry3d T = applyDelta(current, x);
      if (outside(T)) return 1e9;
      return -objective.value(full.score(T, skip, options.measure));
    };
    const Search s = searchFrom(f, Eigen::VectorXd::Zero(6), step / 2, 0, options.maxEvaluationsPerRun);
    result.evaluations += s.evaluations;
    loo.push_back(applyDelta(current, s.x));
  }
  const detail::PoseSpread spread = detail::jackknifeSpread(loo, current);
  result.rotationStdDeg = spread.rotationStdDeg;
  result.translationStd = spread.translationStd;
  return result;
}

}  // namespace fusedet::fusion
