// SPDX-License-Identifier: Apache-2.0
// The run-time dispatch of the scanners' vector paths (fusedet/boost/vector_path.h) against the
// CPU's own flags in /proc/cpuinfo: the widest path the CPU has, narrowed by the test switches.
// That every path decides the same windows is multi_detector_test's and opencv_parity_test's.

#include "fusedet/boost/vector_path.h"

#include <gtest/gtest.h>

#include <fstream>
#include <set>
#include <sstream>
#include <string>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/opencv_cascade.h"

using namespace fusedet::boosting;

namespace {

// The first processor's flags as the kernel lists them (x86: "flags", arm64: "Features").
std::set<std::string> cpuinfoFlags() {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  std::set<std::string> out;
  while (std::getline(in, line)) {
    if (line.rfind("flags", 0) != 0 && line.rfind("Features", 0) != 0) continue;
    std::istringstream words(line.substr(line.find(':') + 1));
    for (std::string w; words >> w;) out.insert(w);
    break;
  }
  return out;
}

// Widest path the kernel's flags allow (FUSEDET_SIMD unset in the test's environment).
int lanesFromFlags(const std::set<std::string>& f) {
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
  if (f.count("avx512f") && f.count("avx512vl")) return 8;
  if (f.count("avx2")) return 4;
#elif defined(__aarch64__)
  return 4;  // NEON is part of every AArch64 CPU (under qemu-user the flags are the x86 host's)
#endif
  (void)f;
  return 1;
}

}  // namespace

TEST(VectorPath, WidestPathIsTheOneTheCpuFlagsAllow) {
  const std::set<std::string> flags = cpuinfoFlags();
  ASSERT_FALSE(flags.empty()) << "no flags line in /proc/cpuinfo";
  const int expected = lanesFromFlags(flags);
  EXPECT_EQ(dispatchedVectorLanes(), expected);
#if defined(__x86_64__)
  // x86 builds only: under qemu-user an arm64 build reads the x86 host's /proc/cpuinfo.
  const std::string ext = cpuVectorExtensions();
  for (const char* name : {"avx2", "avx512f", "avx512vl"})
    EXPECT_EQ(ext.find(name) != std::string::npos, flags.count(name) == 1) << name << " in '" << ext << "'";
#endif
  EXPECT_NE(vectorPathSummary().find("vector path " + vectorPathName(expected)), std::string::npos)
      << vectorPathSummary();
}

TEST(VectorPath, SwitchesNarrowThePath) {
  const int widest = dispatchedVectorLanes();
  setVectorLanesLimit(4);
  EXPECT_EQ(dispatchedVectorLanes(), widest >= 4 ? 4 : 1);
  setVectorLanesLimit(2);  // no two-lane path: scalar
  EXPECT_EQ(dispatchedVectorLanes(), 1);
  setVectorLanesLimit(8);
  EXPECT_EQ(dispatchedVectorLanes(), widest);
  setVectorScanEnabled(false);
  EXPECT_EQ(dispatchedVectorLanes(), 1);
  EXPECT_NE(vectorPathSummary().find("vector path scalar"), std::string::npos);
  setVectorScanEnabled(true);
  EXPECT_EQ(dispatchedVectorLanes(), widest);
}

TEST(VectorPath, NamesOfThePaths) {
#if defined(__aarch64__)
  EXPECT_EQ(vectorPathName(4), "neon");
#else
  EXPECT_EQ(vectorPathName(8), "avx512");
  EXPECT_EQ(vectorPathName(4), "avx2");
#endif
  EXPECT_EQ(vectorPathName(1), "scalar");
}
