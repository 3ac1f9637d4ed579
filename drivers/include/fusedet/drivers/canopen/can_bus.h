// SPDX-License-Identifier: Apache-2.0
#pragma once
// CanBus: what the CANopen master and the motor simulator need from a CAN network. Two
// implementations: SocketCanBus (a Linux raw CAN socket) and InProcessBus::Endpoint (tests and
// simulation, optionally on simulated time). Every frame sent or received passes the recording
// hook, so a candump log of one endpoint holds the whole conversation it took part in.

#include <chrono>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/canopen/can_frame.h"

namespace fusedet::drivers::canopen {

// Receive filter as in CAN_RAW: a frame passes when (frame.id & mask) == (id & mask).
struct CanFilter {
  std::uint32_t id = 0;
  std::uint32_t mask = 0;
  bool matches(const CanFrame& f) const { return (f.id & mask) == (id & mask); }
};

struct CanBusCounters {
  std::uint64_t framesRx = 0;
  std::uint64_t framesTx = 0;
  std::uint64_t errorFrames = 0;  // SocketCAN error frames received (bus-off, error passive, ...)
  std::uint64_t txFailures = 0;   // sends refused (buffer full, bus-off, interface down)
  std::uint64_t timeouts = 0;     // receive() calls that ended without a frame
  std::uint64_t userStamps = 0;   // SocketCAN frames the kernel gave no stamp for (stamped here instead)
};

enum class FrameDirection { kRx, kTx };
using FrameHook = std::function<void(const CanFrame&, FrameDirection)>;

class CanBus {
 public:
  virtual ~CanBus() = default;
  // Queues one frame. Errors: resource_unavailable_try_again (tx buffer full),
  // network_down (bus-off or interface down), no_such_device (interface gone).
  virtual Result<void> send(const CanFrame& frame) = 0;
  // Next frame passing the filters (error frames always pass); timed_out when none arrives in
  // `timeout` (0 = only what is already there).
  virtual Result<CanFrame> receive(std::chrono::microseconds timeout) = 0;
  // Replaces the receive filters (empty = receive everything).
  virtual Result<void> setFilters(const std::vector<CanFilter>& filters) = 0;
  virtual Stamp now() const { return Stamp::now(); }  // the bus's clock (simulated on a simulated bus)
  virtual CanBusCounters counters() const = 0;
  virtual std::string name() const = 0;  // interface name for logs, e.g. "can0"

  void setFrameHook(FrameHook hook) { hook_ = std::move(hook); }

 protected:
  void notify(const CanFrame& f, FrameDirection d) const {
    if (hook_) hook_(f, d);
  }

 private:
  FrameHook hook_;
};

}  // namespace fusedet::drivers::canopen
