// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: an MCAP sensor log (docs/log-format.md) as McapReader reads a file: the
// input is put in an anonymous memory file and opened by path; the index pass and every message
// the cursor yields. McapError is the only exception allowed (a file that is not MCAP).

#include <sys/mman.h>
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <string>

#include "fusedet/drivers/log/mcap_reader.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::drivers::mcap;
  const int fd = ::memfd_create("fuzz.mcap", MFD_CLOEXEC);
  if (fd < 0) return 0;
  for (std::size_t done = 0; done < size;) {
    const ssize_t n = ::write(fd, data + done, size - done);
    if (n <= 0) break;
    done += static_cast<std::size_t>(n);
  }
  try {
    McapReader reader("/proc/self/fd/" + std::to_string(fd));
    auto cursor = reader.messages();
    while (cursor.next()) {
    }
  } catch (const McapError&) {
  }
  ::close(fd);
  return 0;
}
