// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/stamp.h"

#include <cstdio>
#include <ctime>

namespace fusedet {

Stamp Stamp::now() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return Stamp{static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec};
}

std::string Stamp::toString() const {
  const std::int64_t sec = ns / 1'000'000'000;
  std::int64_t frac = ns % 1'000'000'000;
  const bool negative = ns < 0;
  if (frac < 0) frac = -frac;
  char buf[48];
  std::snprintf(buf, sizeof buf, "%s%lld.%09lld", negative && sec == 0 ? "-" : "",
                static_cast<long long>(sec), static_cast<long long>(frac));
  return buf;
}

}  // namespace fusedet
