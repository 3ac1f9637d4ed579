// SPDX-License-Identifier: Apache-2.0
#pragma once
// SerialPort: a raw 8N1 serial line (termios) with poll-based timeouts. Speeds the C library
// knows go through cfsetspeed; others, or any speed the port refuses that way, through the
// termios2 BOTHER interface (arbitrary rates such as 500 kbaud on RS-422 adapters).
//
// Errors are routine (device unplugged, timeouts): every call returns Result, none logs.
// A vanished device reports std::errc::no_such_device (from ENODEV, EIO or POLLHUP).

#include <chrono>
#include <cstdint>
#include <span>
#include <string>

#include "fusedet/core/result.h"
#include "fusedet/drivers/unique_fd.h"

namespace fusedet::drivers {

class SerialPort {
 public:
  SerialPort() = default;

  // Opens `path` non-blocking, raw 8N1, no flow control, at `baud`.
  static Result<SerialPort> open(const std::string& path, int baud);

  // forceTermios2: skip cfsetspeed (tests the BOTHER path on ports that accept both).
  Result<void> setBaud(int baud, bool forceTermios2 = false);
  int baud() const { return baud_; }
  bool usedTermios2() const { return usedTermios2_; }

  // Reads what is available, waiting up to `timeout` for the first byte; 0 = timed out.
  Result<std::size_t> read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout);
  // Writes all bytes, waiting up to `timeout` for the line to take them.
  Result<void> write(std::span<const std::uint8_t> bytes, std::chrono::microseconds timeout);
  // Discards unread input (tcflush TCIFLUSH).
  void flushInput();
  // Waits until the output has been transmitted (tcdrain), e.g. before changing speed.
  void drain();

  bool isOpen() const { return fd_.valid(); }
  const std::string& path() const { return path_; }
  int fd() const { return fd_.get(); }
  void close() { fd_.reset(); }

 private:
  UniqueFd fd_;
  std::string path_;
  int baud_ = 0;
  bool usedTermios2_ = false;
};

namespace detail {
// termios2 ioctls live apart: <asm/termbits.h> clashes with <termios.h>. Return 0 or -errno.
int setBaudTermios2(int fd, int baud);
int getBaudTermios2(int fd, int* outputBaud);
}  // namespace detail

}  // namespace fusedet::drivers
