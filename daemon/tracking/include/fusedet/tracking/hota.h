// SPDX-License-Identifier: Apache-2.0
#pragma once
// HOTA (Luiten et al., IJCV 2021, "HOTA: A Higher Order Metric for Evaluating Multi-Object
// Tracking") with IoU similarity, at the 19 localisation thresholds alpha = 0.05, 0.10, ..., 0.95,
// as TrackEval computes it: a global alignment score per (truth id, hypothesis id) pair from the
// whole sequence; per frame an optimal assignment maximising alignment x IoU; at each alpha the
// assigned pairs with IoU >= alpha are TPs, DetA = TP / (TP + FN + FP), AssA = mean over TPs of
// TPA / (TPA + FNA + FPA) of their id pair, HOTA = sqrt(DetA AssA), LocA = mean IoU of the TPs.
// The reported HOTA, DetA, AssA and LocA are the means over alpha.

#include <array>

#include "fusedet/tracking/mot_sequence.h"

namespace fusedet::tracking {

struct Hota {
  static constexpr int kAlphas = 19;
  static double alpha(int k) { return 0.05 * (k + 1); }
  std::array<double, kAlphas> hota{}, detA{}, assA{}, locA{};
  double meanHota() const;
  double meanDetA() const;
  double meanAssA() const;
  double meanLocA() const;
};

Hota hota(const MotSequence& sequence);

}  // namespace fusedet::tracking
