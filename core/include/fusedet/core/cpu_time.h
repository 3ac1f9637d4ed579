// SPDX-License-Identifier: Apache-2.0
#pragma once
// CPU-time clocks, beside Stamp's wall clock (stamp.h): stage timings and benchmarks report CPU
// time next to wall time, since on a shared machine wall time also counts waiting for a core.

namespace fusedet {

// CPU time the calling thread has used, in milliseconds (CLOCK_THREAD_CPUTIME_ID).
double threadCpuMs();
// CPU time all threads of this process have used, in milliseconds (CLOCK_PROCESS_CPUTIME_ID).
double processCpuMs();

}  // namespace fusedet
