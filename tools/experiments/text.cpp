// SPDX-License-Identifier: Apache-2.0
#include "text.h"

#include <cstdio>

namespace fusedet::tools::experiments {
std::string shortNum(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string joined(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

std::string foldsText(std::size_t folds, std::size_t drives) {
  return folds == drives ? "leave-one-drive-out (" + std::to_string(folds) + " folds)"
                         : std::to_string(folds) + " drive-disjoint folds";
}

std::string learningText(const std::vector<std::size_t>& counts, const std::string& sep) {
  if (counts.empty()) return "none";
  std::vector<std::string> v;
  for (std::size_t k : counts) v.push_back(k == 0 ? "all" : std::to_string(k));
  return joined(v, sep);
}

}  // namespace fusedet::tools::experiments
