// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/stream_state.h"

namespace fusedet::drivers {

std::string_view toString(StreamState s) {
  switch (s) {
    case StreamState::kStopped: return "stopped";
    case StreamState::kConnecting: return "connecting";
    case StreamState::kStreaming: return "streaming";
    case StreamState::kBackingOff: return "backing off";
  }
  return "unknown";
}

}  // namespace fusedet::drivers
