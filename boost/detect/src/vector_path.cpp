// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/vector_path.h"

#include <algorithm>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <string_view>

#if defined(__aarch64__) && defined(__linux__)
#include <asm/hwcap.h>
#include <sys/auxv.h>
#endif

#include "fusedet/boost/detector.h"
#include "fusedet/boost/opencv_cascade.h"

namespace fusedet::boosting {

namespace {

constexpr const char* kEnv = "FUSEDET_SIMD";

// Windows per step of a path named as FUSEDET_SIMD takes it, 0 for an unknown name.
int lanesNamed(std::string_view name) {
#if defined(__aarch64__)
  if (name == "neon") return 4;
#else
  if (name == "avx512") return 8;
  if (name == "avx2") return 4;
#endif
  if (name == "scalar") return 1;
  return 0;
}

#if defined(__aarch64__)
constexpr const char* kPathNames = "neon, scalar";
#else
constexpr const char* kPathNames = "avx512, avx2, scalar";
#endif

// FUSEDET_SIMD's limit, read once: 8 (no limit) when unset or unknown.
int environmentLimit() {
  static const int limit = [] {
    const char* v = std::getenv(kEnv);
    if (!v) return 8;
    const int lanes = lanesNamed(v);
    if (lanes == 0) {
      std::fprintf(stderr, "fusedet: %s=%s is not a vector path (%s); ignored\n", kEnv, v, kPathNames);
      return 8;
    }
    return lanes;
  }();
  return limit;
}

std::atomic<bool> gVectorEnabled{true};
std::atomic<int> gVectorLanesLimit{8};

}  // namespace

void setVectorScanEnabled(bool enabled) { gVectorEnabled = enabled; }
void setVectorLanesLimit(int lanes) { gVectorLanesLimit = lanes; }

int cpuVectorLanes() {
#if defined(__x86_64__) && defined(__GNUC__)
  static const int lanes = __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") ? 8
                           : __builtin_cpu_supports("avx2")                                         ? 4
                                                                                                    : 1;
  return lanes;
#elif defined(__aarch64__) && defined(__GNUC__)
  return 4;  // NEON (Advanced SIMD) is part of every AArch64 CPU
#else
  return 1;
#endif
}

int dispatchedVectorLanes() {
  if (!gVectorEnabled.load(std::memory_order_relaxed)) return 1;
  const int most = std::min({cpuVectorLanes(), environmentLimit(), gVectorLanesLimit.load(std::memory_order_relaxed)});
  for (int lanes : {8, 4})
    if (lanes <= most) return lanes;
  return 1;
}

std::string vectorPathName(int lanes) {
#if defined(__aarch64__)
  if (lanes >= 4) return "neon";
#else
  if (lanes >= 8) return "avx512";
  if (lanes >= 4) return "avx2";
#endif
  return "scalar";
}

std::string cpuVectorExtensions() {
  std::string out;
#if defined(__x86_64__) && defined(__GNUC__)
  auto add = [&](const char* name, bool has) {
    if (!has) return;
    if (!out.empty()) out += ' ';
    out += name;
  };
  add("sse4.2", __builtin_cpu_supports("sse4.2"));
  add("avx", __builtin_cpu_supports("avx"));
  add("avx2", __builtin_cpu_supports("avx2"));
  add("fma", __builtin_cpu_supports("fma"));
  add("avx512f", __builtin_cpu_supports("avx512f"));
  add("avx512vl", __builtin_cpu_supports("avx512vl"));
  add("avx512bw", __builtin_cpu_supports("avx512bw"));
#elif defined(__aarch64__) && defined(__linux__)
  if (getauxval(AT_HWCAP) & HWCAP_ASIMD) out = "asimd";  // NEON, as the kernel names it
#endif
  return out.empty() ? "none" : out;
}

std::string vectorPathSummary() {
  const char* env = std::getenv(kEnv);
  std::string out = "vector path " + vectorPathName(dispatchedVectorLanes()) + " (";
  out += kEnv;
  out += env ? std::string("=") + env : std::string(" unset");
  out += "; CPU: " + cpuVectorExtensions() + ")";
  return out;
}

}  // namespace fusedet::boosting
