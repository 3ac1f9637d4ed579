// SPDX-License-Identifier: Apache-2.0
#include "memory_file.h"

#include <sys/mman.h>
#include <unistd.h>

namespace fusedet::fuzz {

MemoryFile::MemoryFile(const std::uint8_t* data, std::size_t size) {
  fd_ = ::memfd_create("fuzz-input", MFD_CLOEXEC);
  for (std::size_t done = 0; fd_ >= 0 && done < size;) {
    const ssize_t n = ::write(fd_, data + done, size - done);
    if (n <= 0) {
      ::close(fd_);
      fd_ = -1;
      break;
    }
    done += static_cast<std::size_t>(n);
  }
}

MemoryFile::~MemoryFile() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace fusedet::fuzz
