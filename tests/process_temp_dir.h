// SPDX-License-Identifier: Apache-2.0
#pragma once
// One folder in the system's temp directory per test process, `fusedet-test-<pid>`: made on first
// use and removed with all it holds when the process exits normally, so running the suite again
// and again leaves nothing behind (a test that crashes keeps it, to look at). A forked child that
// exits without exec leaves it to its parent.

#include <unistd.h>

#include <filesystem>
#include <string>
#include <system_error>

namespace fusedet::test {

inline const std::filesystem::path& processTempDir() {
  struct Dir {
    pid_t owner = ::getpid();
    std::filesystem::path path =
        std::filesystem::temp_directory_path() / ("fusedet-test-" + std::to_string(::getpid()));
    Dir() { std::filesystem::create_directories(path); }
    ~Dir() {
      std::error_code ignored;  // nothing to report to at exit
      if (::getpid() == owner) std::filesystem::remove_all(path, ignored);
    }
  };
  static const Dir dir;
  return dir.path;
}

}  // namespace fusedet::test
