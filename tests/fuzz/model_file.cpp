// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a cascade model file (fusedet/boost/model_io.h). modelFromText may only return a
// cascade or throw ModelError naming the place; an accepted model is written again and must read
// back to the same text.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fusedet/boost/model_io.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::boosting;
  const std::string text(reinterpret_cast<const char*>(data), size);
  try {
    const Cascade cascade = modelFromText(text, "fuzz.json");
    const std::string written = modelToText(cascade);
    if (modelToText(modelFromText(written, "written.json")) != written) std::abort();
  } catch (const ModelError&) {
  }
  return 0;
}
