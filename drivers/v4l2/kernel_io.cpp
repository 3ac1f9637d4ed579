// SPDX-License-Identifier: Apache-2.0
// KernelV4l2Io: V4l2Io on a real device node.

#include <fcntl.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/mman.h>
#include <sys/stat.h>

#include <cerrno>

#include "fusedet/drivers/unique_fd.h"
#include "fusedet/drivers/v4l2/v4l2_io.h"

namespace fusedet::drivers::v4l2 {
namespace {

class KernelV4l2Io final : public V4l2Io {
 public:
  Result<void> open(const std::string& path) override {
    struct stat st {};
    if (::stat(path.c_str(), &st) != 0) return errnoError(errno, "open");
    if (!S_ISCHR(st.st_mode))
      return makeError(std::errc::inappropriate_io_control_operation, "not a character device");
    const int fd = ::open(path.c_str(), O_RDWR | O_NONBLOCK | O_CLOEXEC);
    if (fd < 0) return errnoError(errno, "open");
    fd_.reset(fd);
    return {};
  }
  void close() override { fd_.reset(); }
  bool isOpen() const override { return fd_.valid(); }

  int ioctl(unsigned long request, void* arg) override {
    if (!fd_.valid()) return EBADF;
    for (;;) {
      if (::ioctl(fd_.get(), request, arg) == 0) return 0;
      if (errno != EINTR) return errno;
    }
  }

  Result<std::span<std::uint8_t>> map(std::size_t length, std::uint32_t offset) override {
    void* p = ::mmap(nullptr, length, PROT_READ | PROT_WRITE, MAP_SHARED, fd_.get(), static_cast<off_t>(offset));
    if (p == MAP_FAILED) return errnoError(errno, "mmap");
    return std::span<std::uint8_t>(static_cast<std::uint8_t*>(p), length);
  }
  void unmap(std::span<std::uint8_t> mapping) override { ::munmap(mapping.data(), mapping.size()); }

  Result<PollResult> poll(std::chrono::milliseconds timeout) override {
    const auto deadline = std::chrono::steady_clock::now() + timeout;
    for (;;) {
      pollfd p{fd_.get(), POLLIN, 0};
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now());
      const int n = ::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(0, left.count())));
      if (n < 0 && errno == EINTR) continue;
      if (n < 0) return errnoError(errno, "poll");
      if (n == 0) return PollResult::kTimeout;
      if (p.revents & POLLIN) return PollResult::kReadable;
      return PollResult::kError;
    }
  }

 private:
  UniqueFd fd_;
};

}  // namespace

std::unique_ptr<V4l2Io> makeKernelIo() { return std::make_unique<KernelV4l2Io>(); }

}  // namespace fusedet::drivers::v4l2
