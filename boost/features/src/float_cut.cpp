// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/float_cut.h"

#include <cmath>
#include <limits>

namespace fusedet::boosting {

namespace {
// Rounding to float as the stumps do it (round to nearest even; beyond FLT_MAX to infinity).
bool roundsBelow(double v, float threshold) { return static_cast<float>(v) < threshold; }
}  // namespace

double floatCut(float threshold) {
  if (std::isnan(threshold)) return std::numeric_limits<double>::quiet_NaN();
  constexpr double kInf = std::numeric_limits<double>::infinity();
  if (threshold == -std::numeric_limits<float>::infinity()) return -kInf;
  // Half an ulp of FLT_MAX (2^104 / 2): the float range ends half way to 2^128.
  const double beyondMax = double(std::numeric_limits<float>::max()) + std::ldexp(1.0, 103);
  // Candidate: the midpoint between the float below the threshold and the threshold (exact in
  // double); it rounds to one of the two (ties to even), so the cut is it or the double above it.
  const float below = std::nextafter(threshold, -std::numeric_limits<float>::infinity());
  double cut = 0;
  if (threshold == std::numeric_limits<float>::infinity())
    cut = beyondMax;
  else if (below == -std::numeric_limits<float>::infinity())
    cut = -beyondMax;
  else
    cut = (double(below) + double(threshold)) * 0.5;
  if (roundsBelow(cut, threshold)) cut = std::nextafter(cut, kInf);
  return cut;
}

}  // namespace fusedet::boosting
