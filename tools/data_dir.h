// SPDX-License-Identifier: Apache-2.0
#pragma once
// Where the commands find the shared KITTI data by default: $FUSEDET_DATA, else ../shared/data
// relative to the working directory (the layout of a checkout beside shared/).

#include <cstdlib>
#include <filesystem>

namespace fusedet::tools {

inline std::filesystem::path defaultDataDir() {
  if (const char* env = std::getenv("FUSEDET_DATA"); env && *env) return env;
  return std::filesystem::path("..") / "shared" / "data";
}

}  // namespace fusedet::tools
