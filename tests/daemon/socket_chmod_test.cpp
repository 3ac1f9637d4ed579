// SPDX-License-Identifier: Apache-2.0
// Issue 37: bindUnixSocket did not check chmod, so a socket whose `socket.mode` was never applied
// was served with whatever mode the umask left. chmod on a socket file just bound by its owner
// does not fail by itself, so this program defines its own chmod (the linker takes it, for the
// calls from the statically linked fusedet_daemon too, before libc's) that fails on request.

#include <fcntl.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <string>
#include <system_error>

#include "fusedet/daemon/server.h"

namespace {
std::atomic<int> chmodErrno{0};  // non-zero: chmod fails with it
}  // namespace

extern "C" int chmod(const char* path, mode_t mode) noexcept {
  if (const int e = chmodErrno.load()) {
    errno = e;
    return -1;
  }
  return static_cast<int>(::syscall(SYS_fchmodat, AT_FDCWD, path, mode));
}

TEST(SocketChmod, AFailedChmodRefusesTheSocketAndSaysWhy) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("fusedet-chmod-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  const std::string path = (dir / "d.sock").string();
  chmodErrno = EROFS;
  try {
    (void)fusedet::daemon::bindUnixSocket(path, {0640, {}});
    ADD_FAILURE() << "served a socket whose mode was not applied";
  } catch (const std::system_error& e) {
    EXPECT_NE(std::string(e.what()).find("socket.mode: chmod 0640 " + path), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(std::strerror(EROFS)), std::string::npos) << e.what();
  }
  // With chmod working again the same call serves, with the mode asked for (the file left by the
  // failed call is a stale socket: nobody listens on it).
  chmodErrno = 0;
  const auto fd = fusedet::daemon::bindUnixSocket(path, {0640, {}});
  EXPECT_TRUE(fd.valid());
  struct stat st {};
  ASSERT_EQ(::stat(path.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0640u);
  fs::remove_all(dir);
}
