// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which vector path the scanners run, chosen at run time: the widest the CPU has (x86: AVX-512 with
// avx512f + avx512vl: eight windows per step; AVX2: four; arm64: NEON, four; scalar: one),
// narrowed by
//   - the environment variable FUSEDET_SIMD (read once, at the first scan): `avx512`, `avx2` (x86)
//     or `neon` (arm64), or `scalar` - the widest path allowed, so benchmarks and tests can run a
//     narrower path than the CPU's (a wider one than the CPU has falls back to the CPU's widest);
//     any other value is reported on stderr and ignored;
//   - setVectorLanesLimit() (detector.h) and setVectorScanEnabled(false) (opencv_cascade.h), the
//     process-wide switches tests use to compare the paths.
// Every path decides the same windows with the same scores, bit for bit (tests/boost/detect).

#include <string>

namespace fusedet::boosting {

// The widest path the CPU has, in windows per step: 8 (AVX-512), 4 (AVX2, NEON) or 1.
int cpuVectorLanes();

// The path the scanners take now, in windows per step: the CPU's widest within FUSEDET_SIMD and
// the switches above (the one-pass scanner takes the scalar path for models reading more than
// eight layer grids; the OpenCV-cascade scanner has one vector path, eight windows with AVX2, which
// runs whenever this is 4 or more).
int dispatchedVectorLanes();

// "avx512", "avx2" or "scalar" for 8, 4 or 1 windows per step ("neon" or "scalar" on arm64).
std::string vectorPathName(int lanes);

// The CPU's vector extensions the paths care about, space-separated (e.g. "avx2 avx512f
// avx512vl"; "asimd" on arm64), or "none".
std::string cpuVectorExtensions();

// One line for --version and benchmarks: "vector path avx2 (FUSEDET_SIMD=avx2; CPU: avx2 avx512f avx512vl)".
std::string vectorPathSummary();

}  // namespace fusedet::boosting
