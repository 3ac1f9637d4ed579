// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/percentile.h"

#include <algorithm>
#include <cmath>

namespace fusedet {

double percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  const double rank = std::ceil(q * static_cast<double>(values.size()));
  const auto i = static_cast<std::size_t>(std::clamp(rank, 1.0, static_cast<double>(values.size()))) - 1;
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(i), values.end());
  return values[i];
}

}  // namespace fusedet
