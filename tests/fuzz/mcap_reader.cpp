// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: an MCAP sensor log (docs/log-format.md) as McapReader reads a file: the
// input is put in an anonymous memory file and opened by path; the index pass and every message
// the cursor yields. McapError is the only exception allowed (a file that is not MCAP).

#include <cstddef>
#include <cstdint>

#include "fusedet/drivers/log/mcap_reader.h"
#include "memory_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::drivers::mcap;
  const fusedet::fuzz::MemoryFile file(data, size);
  if (!file.ok()) return 0;
  try {
    McapReader reader(file.path());
    auto cursor = reader.messages();
    while (cursor.next()) {
    }
  } catch (const McapError&) {
  }
  return 0;
}
