// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/cpu_time.h"

#include <ctime>

namespace fusedet {

namespace {
double clockMs(clockid_t clock) {
  timespec t{};
  clock_gettime(clock, &t);
  return static_cast<double>(t.tv_sec) * 1e3 + static_cast<double>(t.tv_nsec) * 1e-6;
}
}  // namespace

double threadCpuMs() { return clockMs(CLOCK_THREAD_CPUTIME_ID); }
double processCpuMs() { return clockMs(CLOCK_PROCESS_CPUTIME_ID); }

}  // namespace fusedet
