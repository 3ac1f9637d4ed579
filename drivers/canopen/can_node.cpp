// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/can_node.h"

namespace fusedet::drivers::canopen {

Result<void> runNode(CanBus& bus, CanNode& node, const std::atomic<bool>& stop, std::chrono::microseconds tick) {
  while (!stop.load()) {
    auto f = bus.receive(tick);
    if (f) {
      node.onFrame(*f);
      // Drain what else is there before polling, so a burst is handled in one go.
      for (int i = 0; i < 64; ++i) {
        auto more = bus.receive(std::chrono::microseconds(0));
        if (!more) break;
        node.onFrame(*more);
      }
    } else if (f.error().code != std::errc::timed_out) {
      return f.error();
    }
    node.poll(bus.now());
  }
  return {};
}

}  // namespace fusedet::drivers::canopen
