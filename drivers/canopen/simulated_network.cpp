// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/simulated_network.h"

namespace fusedet::drivers::canopen {

SimulatedNetwork::SimulatedNetwork(std::string busName, Stamp start, std::chrono::microseconds step)
    : clock_(start.ns), step_(step), bus_(std::move(busName), [this] { return Stamp{clock_.load()}; }) {}

InProcessBus::Endpoint& SimulatedNetwork::connect() {
  endpoints_.push_back(bus_.connect());
  return *endpoints_.back();
}

void SimulatedNetwork::attach(CanNode& node, InProcessBus::Endpoint& endpoint) { nodes_.push_back({&node, &endpoint}); }

void SimulatedNetwork::step() {
  clock_ += std::chrono::nanoseconds(step_).count();
  const Stamp t = now();
  for (Attached& a : nodes_) a.node->poll(t);
  // Deliver until quiet; the bound stops two nodes that answer each other forever.
  for (int round = 0; round < 64; ++round) {
    bool any = false;
    for (Attached& a : nodes_) {
      while (a.endpoint->pending() > 0) {
        auto f = a.endpoint->receive(std::chrono::microseconds(0));
        if (!f) break;
        a.node->onFrame(*f);
        any = true;
      }
    }
    if (!any) break;
  }
}

void SimulatedNetwork::advance(std::chrono::nanoseconds duration) {
  const std::int64_t end = clock_.load() + duration.count();
  while (clock_.load() < end) step();
}

bool SimulatedNetwork::runUntil(const std::function<bool()>& done, std::chrono::nanoseconds limit) {
  const std::int64_t end = clock_.load() + limit.count();
  while (!done()) {
    if (clock_.load() >= end) return false;
    step();
  }
  return true;
}

}  // namespace fusedet::drivers::canopen
