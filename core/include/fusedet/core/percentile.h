// SPDX-License-Identifier: Apache-2.0
#pragma once
// The one percentile every figure uses (status latencies, benchmarks, test reports): nearest rank,
// so a reported p99 is a value that was measured, never one interpolated between two.

#include <vector>

namespace fusedet {

// Nearest-rank percentile, q in [0, 1] (0.99 = p99; q <= 1/n gives the smallest): the value of
// rank ceil(q * n) among the sorted values. 0 for no values.
double percentile(std::vector<double> values, double q);

}  // namespace fusedet
