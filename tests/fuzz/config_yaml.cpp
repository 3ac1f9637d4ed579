// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a fusedetd config file (config/fusedet.yaml's keys). parseConfig may only
// return a Config or throw ConfigError (what --check-config and SIGHUP report); any other
// exception, crash or hang is a finding. An accepted config must survive its own dump.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string>

#include "fusedet/daemon/config.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::daemon;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Config config;
  try {
    config = parseConfig(text, "fuzz.yaml");
  } catch (const ConfigError&) {
    return 0;
  }
  const std::string dumped = dumpConfig(config);
  if (dumpConfig(parseConfig(dumped, "dump.yaml")) != dumped) std::abort();  // the dump round-trips
  return 0;
}
