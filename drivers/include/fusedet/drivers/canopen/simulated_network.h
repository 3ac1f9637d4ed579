// SPDX-License-Identifier: Apache-2.0
#pragma once
// SimulatedNetwork: an InProcessBus on a simulated clock with the nodes attached to it. advance()
// moves time in fixed steps; in each step every node is polled and all frames in flight are
// delivered (a response can come in the same step, i.e. within `step`). Deterministic and
// independent of machine load: tests run minutes of nodding in well under a second.

#include <atomic>
#include <chrono>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "fusedet/drivers/canopen/can_node.h"
#include "fusedet/drivers/canopen/inprocess_bus.h"

namespace fusedet::drivers::canopen {

class SimulatedNetwork {
 public:
  explicit SimulatedNetwork(std::string busName = "sim0", Stamp start = Stamp::fromSeconds(1000.0),
                            std::chrono::microseconds step = std::chrono::microseconds(1000));

  // A new endpoint on the bus; attach() the node that uses it (the network owns the endpoint).
  InProcessBus::Endpoint& connect();
  void attach(CanNode& node, InProcessBus::Endpoint& endpoint);

  Stamp now() const { return Stamp{clock_.load()}; }
  void advance(std::chrono::nanoseconds duration);
  // Advances until `done()` or `limit` has passed; true if done.
  bool runUntil(const std::function<bool()>& done, std::chrono::nanoseconds limit);
  InProcessBus& bus() { return bus_; }

 private:
  void step();

  std::atomic<std::int64_t> clock_;
  std::chrono::microseconds step_;
  InProcessBus bus_;
  std::vector<std::unique_ptr<InProcessBus::Endpoint>> endpoints_;
  struct Attached {
    CanNode* node;
    InProcessBus::Endpoint* endpoint;
  };
  std::vector<Attached> nodes_;
};

}  // namespace fusedet::drivers::canopen
