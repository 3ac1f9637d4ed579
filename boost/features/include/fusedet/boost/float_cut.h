// SPDX-License-Identifier: Apache-2.0
#pragma once
// A stump compares its feature value rounded to float with a float threshold:
// static_cast<float>(v) < threshold. Rounding to float is monotone, so that test is a comparison of
// the double v itself with one double, the "cut": the smallest double that rounds to threshold or
// above. The scanner uses it to decide most windows without rounding (and without the exact
// division that makes v, see window_scanner.h), with exactly the same outcome.

namespace fusedet::boosting {

// The double c with  static_cast<float>(v) < threshold  <=>  v < c  for every double v that is not
// NaN (a NaN v is never below; neither side is true then). threshold NaN -> NaN (nothing is below),
// -inf -> -inf, +inf -> the midpoint between FLT_MAX and 2^128 (the smallest double that rounds to
// +inf).
double floatCut(float threshold);

}  // namespace fusedet::boosting
