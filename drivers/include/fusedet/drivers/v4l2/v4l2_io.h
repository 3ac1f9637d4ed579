// SPDX-License-Identifier: Apache-2.0
#pragma once
// V4l2Io: the only door between V4l2Camera and the kernel: open, ioctl, mmap, poll. The camera's
// logic (negotiation, buffer bookkeeping, timestamps, sequence gaps, restarts) runs unchanged
// against KernelV4l2Io (a /dev/videoN node) or against a fake device in tests.

#include <chrono>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <span>
#include <string>

#include "fusedet/core/result.h"

namespace fusedet::drivers::v4l2 {

enum class PollResult { kReadable, kTimeout, kError };  // kError: POLLERR/POLLHUP (gone, not streaming)

class V4l2Io {
 public:
  virtual ~V4l2Io() = default;
  // Opens the node non-blocking. Errors (context without the path; the caller adds it):
  // no_such_file_or_directory (missing),
  // inappropriate_io_control_operation (exists but is not a character device), or the errno.
  virtual Result<void> open(const std::string& path) = 0;
  virtual void close() = 0;
  virtual bool isOpen() const = 0;
  // The ioctl with EINTR retried: 0 or the errno.
  virtual int ioctl(unsigned long request, void* arg) = 0;
  virtual Result<std::span<std::uint8_t>> map(std::size_t length, std::uint32_t offset) = 0;
  virtual void unmap(std::span<std::uint8_t> mapping) = 0;
  virtual Result<PollResult> poll(std::chrono::milliseconds timeout) = 0;
};

// The real thing: open(2), ioctl(2), mmap(2), poll(2) on a device node.
std::unique_ptr<V4l2Io> makeKernelIo();

}  // namespace fusedet::drivers::v4l2
