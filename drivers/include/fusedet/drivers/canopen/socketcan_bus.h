// SPDX-License-Identifier: Apache-2.0
#pragma once
// SocketCanBus: a Linux raw CAN socket (PF_CAN, SOCK_RAW, CAN_RAW) bound to one interface
// (can0, vcan0, ...). Non-blocking: every wait is a poll() with a timeout. Receive filters are
// the kernel's CAN_RAW_FILTER; all error frames are received (CAN_RAW_ERR_FILTER) and counted.
// Stamps are the kernel's receive time (SO_TIMESTAMPING software stamps, else SIOCGSTAMP),
// moved from CLOCK_REALTIME to CLOCK_MONOTONIC at reception.

#include <mutex>
#include <string>

#include "fusedet/drivers/canopen/can_bus.h"
#include "fusedet/drivers/unique_fd.h"

struct can_frame;

namespace fusedet::drivers::canopen {

class SocketCanBus : public CanBus {
 public:
  // Errors: invalid_argument (bad name), no_such_device ("no CAN interface 'x'" with a hint),
  // address_family_not_supported (kernel without CAN), others from socket/bind.
  Result<void> open(const std::string& interface);
  void close() { fd_.reset(); }
  bool isOpen() const { return fd_.valid(); }
  // True when the kernel gives SO_TIMESTAMPING stamps (else SIOCGSTAMP is asked per frame).
  bool kernelTimestamping() const { return timestamping_; }

  Result<void> send(const CanFrame& frame) override;
  Result<CanFrame> receive(std::chrono::microseconds timeout) override;
  Result<void> setFilters(const std::vector<CanFilter>& filters) override;
  CanBusCounters counters() const override;  // safe from any thread (daemon status)
  std::string name() const override { return interface_; }

 private:
  UniqueFd fd_;
  std::string interface_;
  bool timestamping_ = false;
  mutable std::mutex countersMutex_;
  CanBusCounters counters_;
  void count(std::uint64_t CanBusCounters::*field) {
    std::lock_guard lock(countersMutex_);
    ++(counters_.*field);
  }
  std::int64_t lastRxNs_ = 0;  // the previous received frame's stamp (kept non-decreasing)
};

// Conversions between CanFrame and the kernel's struct can_frame (unit-tested without a socket).
void toKernelFrame(const CanFrame& in, can_frame& out);
CanFrame fromKernelFrame(const can_frame& in);

}  // namespace fusedet::drivers::canopen
