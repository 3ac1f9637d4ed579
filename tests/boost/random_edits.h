// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fuzz-style parser tests: a valid file with 1-4 random edits - a byte replaced by any value, a
// run of up to 8 bytes deleted, one of `tokens` inserted, or the rest cut off - never empty.

#include <random>
#include <string>

namespace fusedet::fuzz {

inline std::string randomlyEdited(std::string s, std::mt19937& rng, const std::string& tokens) {
  const int edits = 1 + int(rng() % 4);
  for (int e = 0; e < edits; ++e) {
    const std::size_t p = rng() % s.size();
    switch (rng() % 4) {
      case 0: s[p] = char(rng() % 256); break;
      case 1: s.erase(p, 1 + rng() % 8); break;
      case 2: s = s.substr(0, p) + tokens[rng() % tokens.size()] + s.substr(p); break;
      default: s.resize(p); break;
    }
    if (s.empty()) s.push_back('x');
  }
  return s;
}

}  // namespace fusedet::fuzz
