// SPDX-License-Identifier: Apache-2.0
#include <cstdint>
#include "fusedet/drivers/canopen/socketcan_bus.h"

#include <linux/can.h>
#include <linux/can/raw.h>
#include <linux/net_tstamp.h>
#include <linux/sockios.h>
#include <net/if.h>
#include <poll.h>
#include <sys/ioctl.h>
#include <sys/socket.h>
#include <time.h>

#include <algorithm>
#include <cerrno>
#include <cstring>

namespace fusedet::drivers::canopen {

namespace {

std::int64_t toNs(const timespec& t) { return std::int64_t{t.tv_sec} * 1'000'000'000 + t.tv_nsec; }

// The kernel stamps in CLOCK_REALTIME; fusedet uses CLOCK_MONOTONIC. The offset is measured
// now as real/mono/real, keeping the tightest of three readings: a thread preempted between two
// clock reads (seen in the real-kernel tier under TCG) would otherwise shift the offset by the
// preemption and put frames received microseconds apart out of order.
Stamp realtimeToMonotonic(std::int64_t realNs) {
  std::int64_t best = 0, width = INT64_MAX;
  for (int i = 0; i < 3; ++i) {
    timespec r1{}, mono{}, r2{};
    ::clock_gettime(CLOCK_REALTIME, &r1);
    ::clock_gettime(CLOCK_MONOTONIC, &mono);
    ::clock_gettime(CLOCK_REALTIME, &r2);
    if (toNs(r2) - toNs(r1) < width) {
      width = toNs(r2) - toNs(r1);
      best = toNs(mono) - (toNs(r1) + toNs(r2)) / 2;
    }
  }
  return Stamp{realNs + best};
}

// Waits until fd is ready for `events`; false on timeout. EINTR restarts with the time left.
Result<bool> waitFor(int fd, short events, std::chrono::microseconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - std::chrono::steady_clock::now() +
                                                                      std::chrono::microseconds(999));
    pollfd p{fd, events, 0};
    int r = ::poll(&p, 1, static_cast<int>(std::max<std::int64_t>(0, left.count())));
    if (r > 0) {
      if (p.revents & (POLLERR | POLLNVAL)) return errnoError(ENODEV, "poll");
      return true;
    }
    if (r == 0) return false;
    if (errno != EINTR) return errnoError(errno, "poll");
  }
}

Error socketError(int err, const std::string& what, const std::string& iface) {
  if (err == ENETDOWN) return makeError(std::errc::network_down, what + " on " + iface + ": interface is down");
  if (err == ENODEV || err == ENXIO) return makeError(std::errc::no_such_device, what + " on " + iface + ": interface gone");
  if (err == EAGAIN || err == ENOBUFS)
    return makeError(std::errc::resource_unavailable_try_again, what + " on " + iface + ": transmit queue full");
  return errnoError(err, what + " on " + iface);
}

}  // namespace

void toKernelFrame(const CanFrame& in, can_frame& out) {
  std::memset(&out, 0, sizeof out);
  out.can_id = in.id & (in.extended || in.error ? CAN_EFF_MASK : CAN_SFF_MASK);
  if (in.extended) out.can_id |= CAN_EFF_FLAG;
  if (in.rtr) out.can_id |= CAN_RTR_FLAG;
  if (in.error) out.can_id = (in.id & CAN_ERR_MASK) | CAN_ERR_FLAG;
  out.can_dlc = std::min<std::uint8_t>(in.len, 8);
  std::memcpy(out.data, in.data.data(), 8);
}

CanFrame fromKernelFrame(const can_frame& in) {
  CanFrame f;
  f.error = (in.can_id & CAN_ERR_FLAG) != 0;
  f.extended = !f.error && (in.can_id & CAN_EFF_FLAG) != 0;
  f.rtr = !f.error && (in.can_id & CAN_RTR_FLAG) != 0;
  f.id = f.error ? (in.can_id & CAN_ERR_MASK) : (in.can_id & (f.extended ? CAN_EFF_MASK : CAN_SFF_MASK));
  f.len = std::min<std::uint8_t>(in.can_dlc, 8);
  std::memcpy(f.data.data(), in.data, 8);
  return f;
}

Result<void> SocketCanBus::open(const std::string& interface) {
  close();
  interface_ = interface;
  if (interface.empty() || interface.size() >= IFNAMSIZ)
    return makeError(std::errc::invalid_argument, "CAN interface name '" + interface + "' is empty or too long");
  const unsigned index = ::if_nametoindex(interface.c_str());
  if (index == 0)
    return makeError(std::errc::no_such_device,
                     "no CAN interface '" + interface + "' (a virtual one: ip link add dev " + interface +
                         " type vcan && ip link set up " + interface + ")");
  UniqueFd fd(::socket(PF_CAN, SOCK_RAW | SOCK_NONBLOCK | SOCK_CLOEXEC, CAN_RAW));
  if (!fd.valid()) {
    if (errno == EAFNOSUPPORT || errno == EPROTONOSUPPORT)
      return makeError(std::errc::address_family_not_supported,
                       "open " + interface + ": the kernel has no CAN support (modprobe can-raw)");
    return errnoError(errno, "open CAN socket for " + interface);
  }
  can_err_mask_t errMask = CAN_ERR_MASK;
  if (::setsockopt(fd.get(), SOL_CAN_RAW, CAN_RAW_ERR_FILTER, &errMask, sizeof errMask) != 0)
    return errnoError(errno, "enable error frames on " + interface);
  int stampFlags = SOF_TIMESTAMPING_RX_SOFTWARE | SOF_TIMESTAMPING_SOFTWARE;
  timestamping_ = ::setsockopt(fd.get(), SOL_SOCKET, SO_TIMESTAMPING, &stampFlags, sizeof stampFlags) == 0;
  sockaddr_can addr{};
  addr.can_family = AF_CAN;
  addr.can_ifindex = static_cast<int>(index);
  if (::bind(fd.get(), reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    if (errno == ENODEV) return makeError(std::errc::no_such_device, "'" + interface + "' is not a CAN interface");
    return errnoError(errno, "bind CAN socket to " + interface);
  }
  fd_ = std::move(fd);
  return {};
}

Result<void> SocketCanBus::send(const CanFrame& frame) {
  if (!fd_.valid()) return makeError(std::errc::bad_file_descriptor, "send: CAN socket not open");
  can_frame k;
  toKernelFrame(frame, k);
  for (int attempt = 0;; ++attempt) {
    ssize_t n = ::write(fd_.get(), &k, sizeof k);
    if (n == static_cast<ssize_t>(sizeof k)) break;
    int e = n < 0 ? errno : EIO;
    if (e == EINTR) continue;
    if ((e == EAGAIN || e == ENOBUFS) && attempt < 2) {
      // The tx queue drains at bus speed: give it a few milliseconds before reporting.
      auto ready = waitFor(fd_.get(), POLLOUT, std::chrono::milliseconds(5));
      if (!ready) return ready.error();
      continue;
    }
    count(&CanBusCounters::txFailures);
    return socketError(e, "send", interface_);
  }
  count(&CanBusCounters::framesTx);
  CanFrame sent = frame;
  sent.stamp = Stamp::now();
  notify(sent, FrameDirection::kTx);
  return {};
}

Result<CanFrame> SocketCanBus::receive(std::chrono::microseconds timeout) {
  if (!fd_.valid()) return makeError(std::errc::bad_file_descriptor, "receive: CAN socket not open");
  for (;;) {
    can_frame k{};
    iovec iov{&k, sizeof k};
    alignas(cmsghdr) char control[CMSG_SPACE(sizeof(timespec) * 3) + CMSG_SPACE(sizeof(timeval))];
    msghdr msg{};
    msg.msg_iov = &iov;
    msg.msg_iovlen = 1;
    msg.msg_control = control;
    msg.msg_controllen = sizeof control;
    ssize_t n = ::recvmsg(fd_.get(), &msg, 0);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno != EAGAIN && errno != EWOULDBLOCK) return socketError(errno, "receive", interface_);
      auto ready = waitFor(fd_.get(), POLLIN, timeout);
      if (!ready) return socketError(ENODEV, "receive", interface_);
      if (!*ready) {
        count(&CanBusCounters::timeouts);
        return makeError(std::errc::timed_out, "receive on " + interface_);
      }
      timeout = std::chrono::microseconds(0);  // data is there now; a second EAGAIN ends the call
      continue;
    }
    if (n != static_cast<ssize_t>(sizeof k)) continue;  // not a classic CAN frame (CAN FD is off)
    CanFrame f = fromKernelFrame(k);
    std::int64_t realNs = 0;
    for (cmsghdr* c = CMSG_FIRSTHDR(&msg); c; c = CMSG_NXTHDR(&msg, c)) {
      if (c->cmsg_level == SOL_SOCKET && c->cmsg_type == SO_TIMESTAMPING) {
        timespec ts[3];
        std::memcpy(ts, CMSG_DATA(c), sizeof ts);
        realNs = toNs(ts[0]);  // [0] = software stamp
      }
    }
    if (realNs == 0) {
      timeval tv{};
      if (::ioctl(fd_.get(), SIOCGSTAMP, &tv) == 0) realNs = std::int64_t{tv.tv_sec} * 1'000'000'000 + tv.tv_usec * 1000;
    }
    f.kernelStamp = realNs != 0;
    f.stamp = f.kernelStamp ? realtimeToMonotonic(realNs) : Stamp::now();
    // Kernel stamps are in reception order: any residual offset error never reorders them.
    if (f.stamp.ns < lastRxNs_) f.stamp = Stamp{lastRxNs_};
    lastRxNs_ = f.stamp.ns;
    if (!f.kernelStamp) count(&CanBusCounters::userStamps);
    count(&CanBusCounters::framesRx);
    if (f.error) count(&CanBusCounters::errorFrames);
    notify(f, FrameDirection::kRx);
    return f;
  }
}

CanBusCounters SocketCanBus::counters() const {
  std::lock_guard lock(countersMutex_);
  return counters_;
}

Result<void> SocketCanBus::setFilters(const std::vector<CanFilter>& filters) {
  if (!fd_.valid()) return makeError(std::errc::bad_file_descriptor, "set filters: CAN socket not open");
  std::vector<can_filter> k;
  for (const CanFilter& f : filters) k.push_back(can_filter{f.id, f.mask});
  // An empty CAN_RAW_FILTER list receives nothing; "everything" is one filter with mask 0.
  if (k.empty()) k.push_back(can_filter{0, 0});
  if (::setsockopt(fd_.get(), SOL_CAN_RAW, CAN_RAW_FILTER, k.data(), static_cast<socklen_t>(k.size() * sizeof(can_filter))) != 0)
    return errnoError(errno, "set CAN filters on " + interface_);
  return {};
}

}  // namespace fusedet::drivers::canopen
