// SPDX-License-Identifier: Apache-2.0
#pragma once
// MemoryFile: a fuzz input as a file with a path (an anonymous memfd, /proc/self/fd/N), for the
// parsers that read a file by name. Closed when destroyed.

#include <cstddef>
#include <cstdint>
#include <string>

namespace fusedet::fuzz {

class MemoryFile {
 public:
  MemoryFile(const std::uint8_t* data, std::size_t size);
  ~MemoryFile();
  MemoryFile(const MemoryFile&) = delete;
  MemoryFile& operator=(const MemoryFile&) = delete;

  bool ok() const { return fd_ >= 0; }
  std::string path() const { return "/proc/self/fd/" + std::to_string(fd_); }

 private:
  int fd_ = -1;
};

}  // namespace fusedet::fuzz
