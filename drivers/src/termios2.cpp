// SPDX-License-Identifier: Apache-2.0
// termios2 (BOTHER) speed setting, kept in its own file because <asm/termbits.h> and the C
// library's <termios.h> define the same names differently.
#include <asm/ioctls.h>
#include <asm/termbits.h>
#include <cerrno>

extern "C" int ioctl(int fd, unsigned long request, ...) noexcept;

namespace fusedet::drivers::detail {

int setBaudTermios2(int fd, int baud) {
  struct termios2 t {};
  if (ioctl(fd, TCGETS2, &t) != 0) return -errno;
  t.c_cflag &= ~static_cast<tcflag_t>(CBAUD | (CBAUD << IBSHIFT));
  t.c_cflag |= BOTHER | (BOTHER << IBSHIFT);
  t.c_ispeed = static_cast<speed_t>(baud);
  t.c_ospeed = static_cast<speed_t>(baud);
  if (ioctl(fd, TCSETS2, &t) != 0) return -errno;
  struct termios2 check {};
  if (ioctl(fd, TCGETS2, &check) != 0) return -errno;
  // Drivers round to what the UART can do; more than 3 % off would break framing.
  const long diff = static_cast<long>(check.c_ospeed) - baud;
  if (diff * 100 > 3L * baud || -diff * 100 > 3L * baud) return -EINVAL;
  return 0;
}

int getBaudTermios2(int fd, int* outputBaud) {
  struct termios2 t {};
  if (ioctl(fd, TCGETS2, &t) != 0) return -errno;
  *outputBaud = static_cast<int>(t.c_ospeed);
  return 0;
}

}  // namespace fusedet::drivers::detail
