// SPDX-License-Identifier: Apache-2.0
#pragma once
// StreamState: what a reconnecting device thread (lms291::ScanStream, v4l2::FrameStream) is doing,
// for the daemon's status.

#include <string_view>

namespace fusedet::drivers {

enum class StreamState { kStopped, kConnecting, kStreaming, kBackingOff };
std::string_view toString(StreamState s);

}  // namespace fusedet::drivers
