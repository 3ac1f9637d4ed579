// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/score_profile.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace fusedet::fusion {

ScoreProfile scoreProfile(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K, const Eigen::Isometry3d& reference,
                          int steps, double rotationStepDeg, double translationStep, const TargetlessOptions& options) {
  if (steps < 1) throw std::invalid_argument("score profile: steps must be >= 1");
  ScoreProfile p{steps, rotationStepDeg, translationStep, {}};
  std::vector<Eigen::Isometry3d> candidates;
  for (int axis = 0; axis < 6; ++axis)
    for (int k = -steps; k <= steps; ++k) {
      Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
      if (axis < 3)
        d.linear() = Eigen::AngleAxisd(p.offset(axis, k) * M_PI / 180.0, Eigen::Vector3d::Unit(axis)).toRotationMatrix();
      else
        d.translation() = p.offset(axis, k) * Eigen::Vector3d::Unit(axis - 3);
      candidates.push_back(d * reference);
    }
  const std::vector<AlignmentScore> all = scoreAlignments(frames, K, reference, candidates, options);
  const auto per = static_cast<std::size_t>(2 * steps + 1);
  for (std::size_t axis = 0; axis < 6; ++axis)
    p.scores[axis].assign(all.begin() + static_cast<std::ptrdiff_t>(axis * per),
                          all.begin() + static_cast<std::ptrdiff_t>((axis + 1) * per));
  return p;
}

double ScoreProfile::peakOffset(int axis, bool mutualInformation) const {
  auto value = [&](int k) {
    const AlignmentScore& s = scores[axis][static_cast<std::size_t>(k + steps)];
    return mutualInformation ? s.mutualInformation : s.edgeAlignment;
  };
  int best = -steps;  // the first of equal values, as the search from -steps up finds it
  for (int k = -steps; k <= steps; ++k)
    if (value(k) > value(best)) best = k;
  return offset(axis, best);
}

std::string formatScoreProfile(const ScoreProfile& p) {
  const char* names[] = {"rot_x", "rot_y", "rot_z", "t_x", "t_y", "t_z"};
  std::string out;
  char buf[160];
  for (int m = 0; m < 2; ++m) {
    auto value = [&](int axis, int k) {
      const AlignmentScore& s = p.scores[axis][static_cast<std::size_t>(k + p.steps)];
      return m == 0 ? s.edgeAlignment : s.mutualInformation;
    };
    std::snprintf(buf, sizeof buf, "profile of %s (camera axes; offsets: rotation deg / translation cm)\n offset     ",
                  m == 0 ? "edges" : "mi");
    out += buf;
    for (const char* n : names) out += (std::snprintf(buf, sizeof buf, " %9s", n), buf);
    out += "\n";
    for (int k = -p.steps; k <= p.steps; ++k) {
      out += (std::snprintf(buf, sizeof buf, "%5.2f/%5.1f", p.offset(0, k), 100 * p.offset(3, k)), buf);
      for (int axis = 0; axis < 6; ++axis) out += (std::snprintf(buf, sizeof buf, " %9.5f", value(axis, k)), buf);
      out += "\n";
    }
    out += "peak at    ";
    for (int axis = 0; axis < 6; ++axis) {
      const double peak = p.peakOffset(axis, m == 1);
      out += (std::snprintf(buf, sizeof buf, " %9.2f", axis < 3 ? peak : 100 * peak), buf);
    }
    out += "\n";
  }
  return out;
}

}  // namespace fusedet::fusion
