// SPDX-License-Identifier: Apache-2.0
#pragma once
// CanNode: something that lives on a CAN bus as an event-driven state machine (the tilt drive
// master, the motor simulator). It never blocks: frames go in through onFrame(), time through
// poll(). Two ways to run nodes: runNode() on real time (a socket or a threaded in-process bus)
// and SimulatedNetwork (simulated_network.h) on simulated time.

#include <atomic>
#include <chrono>

#include "fusedet/core/result.h"
#include "fusedet/drivers/canopen/can_bus.h"

namespace fusedet::drivers::canopen {

class CanNode {
 public:
  virtual ~CanNode() = default;
  virtual void onFrame(const CanFrame& f) = 0;
  virtual void poll(Stamp now) = 0;
};

// Feeds every frame `bus` receives to `node` and polls it at least every `tick`, until *stop
// becomes true (ok) or the bus fails (its error: interface gone or down).
Result<void> runNode(CanBus& bus, CanNode& node, const std::atomic<bool>& stop,
                     std::chrono::microseconds tick = std::chrono::microseconds(1000));

}  // namespace fusedet::drivers::canopen
