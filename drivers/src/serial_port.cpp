// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/serial_port.h"

#include <fcntl.h>
#include <poll.h>
#include <termios.h>
#include <unistd.h>

#include <cerrno>
#include <thread>

namespace fusedet::drivers {

namespace {

speed_t standardSpeed(int baud) {
  switch (baud) {
    case 9600: return B9600;
    case 19200: return B19200;
    case 38400: return B38400;
    case 57600: return B57600;
    case 115200: return B115200;
    case 230400: return B230400;
    case 460800: return B460800;
    case 500000: return B500000;
    case 921600: return B921600;
    default: return B0;
  }
}

// A hung-up line (USB adapter unplugged, pty master closed) shows as EIO/ENODEV/ENXIO.
Error lineError(int err, const std::string& what) {
  if (err == EIO || err == ENODEV || err == ENXIO)
    return Error{std::make_error_code(std::errc::no_such_device), what};
  return errnoError(err, what);
}

int remainingMs(std::chrono::steady_clock::time_point deadline) {
  const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - std::chrono::steady_clock::now());
  if (left.count() <= 0) return 0;
  return static_cast<int>((left.count() + 999) / 1000);
}

}  // namespace

Result<SerialPort> SerialPort::open(const std::string& path, int baud) {
  SerialPort port;
  port.path_ = path;
  port.fd_.reset(::open(path.c_str(), O_RDWR | O_NOCTTY | O_NONBLOCK | O_CLOEXEC));
  if (!port.fd_.valid()) return lineError(errno, "open " + path);
  termios t{};
  if (tcgetattr(port.fd_.get(), &t) != 0) return lineError(errno, "tcgetattr " + path);
  cfmakeraw(&t);
  t.c_cflag |= CLOCAL | CREAD;
  t.c_cflag &= ~static_cast<tcflag_t>(CRTSCTS | CSTOPB | PARENB);
  t.c_iflag &= ~static_cast<tcflag_t>(IXON | IXOFF | IXANY);
  t.c_cc[VMIN] = 0;
  t.c_cc[VTIME] = 0;
  if (tcsetattr(port.fd_.get(), TCSANOW, &t) != 0) return lineError(errno, "tcsetattr " + path);
  if (auto r = port.setBaud(baud); !r) return r.error();
  port.flushInput();
  return port;
}

Result<void> SerialPort::setBaud(int baud, bool forceTermios2) {
  const std::string what = "set " + path_ + " to " + std::to_string(baud) + " baud";
  const speed_t speed = standardSpeed(baud);
  if (speed != B0 && !forceTermios2) {
    termios t{};
    if (tcgetattr(fd_.get(), &t) != 0) return lineError(errno, what);
    cfsetispeed(&t, speed);
    cfsetospeed(&t, speed);
    termios check{};
    if (tcsetattr(fd_.get(), TCSANOW, &t) == 0 && tcgetattr(fd_.get(), &check) == 0 &&
        cfgetospeed(&check) == speed) {
      baud_ = baud;
      usedTermios2_ = false;
      return {};
    }
    if (errno == EIO || errno == ENODEV) return lineError(errno, what);
  }
  // Non-standard rate, or the adapter refused the standard constant: ask for the rate itself.
  if (const int rc = detail::setBaudTermios2(fd_.get(), baud); rc < 0) return lineError(-rc, what + " (termios2)");
  baud_ = baud;
  usedTermios2_ = true;
  return {};
}

Result<std::size_t> SerialPort::read(std::span<std::uint8_t> buffer, std::chrono::microseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    pollfd p{fd_.get(), POLLIN, 0};
    const int rc = ::poll(&p, 1, remainingMs(deadline));
    if (rc < 0) {
      if (errno == EINTR) continue;
      return lineError(errno, "poll " + path_);
    }
    if (rc == 0) return std::size_t{0};
    if ((p.revents & (POLLIN | POLLHUP | POLLERR | POLLNVAL)) == 0) continue;
    const ssize_t n = ::read(fd_.get(), buffer.data(), buffer.size());
    if (n > 0) return static_cast<std::size_t>(n);
    if (n < 0 && errno != EAGAIN && errno != EINTR) return lineError(errno, "read " + path_);
    if (p.revents & (POLLHUP | POLLERR | POLLNVAL))
      return Error{std::make_error_code(std::errc::no_such_device), "read " + path_ + ": line hung up"};
    // Raw mode with VMIN = VTIME = 0 reads 0 when the input vanished between poll and read
    // (a flush, a speed change): not a hang-up. Pause briefly rather than spin on it.
    if (n == 0) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
}

Result<void> SerialPort::write(std::span<const std::uint8_t> bytes, std::chrono::microseconds timeout) {
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  std::size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd_.get(), bytes.data() + done, bytes.size() - done);
    if (n > 0) {
      done += static_cast<std::size_t>(n);
      continue;
    }
    if (n < 0 && errno != EAGAIN && errno != EINTR) return lineError(errno, "write " + path_);
    pollfd p{fd_.get(), POLLOUT, 0};
    const int rc = ::poll(&p, 1, remainingMs(deadline));
    if (rc == 0) return makeError(std::errc::timed_out, "write " + path_);
    if (rc > 0 && (p.revents & (POLLHUP | POLLERR | POLLNVAL)))
      return Error{std::make_error_code(std::errc::no_such_device), "write " + path_ + ": line hung up"};
  }
  return {};
}

void SerialPort::flushInput() {
  if (fd_.valid()) (void)tcflush(fd_.get(), TCIFLUSH);
}

void SerialPort::drain() {
  if (fd_.valid()) (void)tcdrain(fd_.get());
}

}  // namespace fusedet::drivers
