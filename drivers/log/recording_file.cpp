// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/recording_file.h"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <stdexcept>
#include <string>

namespace fusedet::drivers::logs {

std::filesystem::path createRecordingFile(const std::filesystem::path& dir, std::chrono::system_clock::time_point start) {
  const std::time_t t = std::chrono::system_clock::to_time_t(start);
  std::tm utc{};
  gmtime_r(&t, &utc);
  char stamp[32];
  std::strftime(stamp, sizeof stamp, "%Y%m%dT%H%M%SZ", &utc);
  for (int n = 1; n < 100; ++n) {
    char name[64];
    if (n == 1)
      std::snprintf(name, sizeof name, "fusedet-%s.mcap", stamp);
    else
      std::snprintf(name, sizeof name, "fusedet-%s-%d.mcap", stamp, n);
    const std::filesystem::path path = dir / name;
    const int fd = ::open(path.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0666);
    if (fd >= 0) {
      ::close(fd);
      return path;
    }
    if (errno != EEXIST) throw std::runtime_error(dir.string() + ": cannot create a recording: " + std::strerror(errno));
  }
  throw std::runtime_error(dir.string() + ": 99 recordings named fusedet-" + stamp + " already: none created");
}

}  // namespace fusedet::drivers::logs
