// SPDX-License-Identifier: Apache-2.0
#pragma once
// LiveServer: the live view's listener (docs/live-view.md), one thread ("fd-live", Boost.Asio).
// One port serves both: an HTTP GET gets the page (daemon/web/, built into fusedetd); a WebSocket
// upgrade asking for subprotocol foxglove.websocket.v1 becomes a viewer - serverInfo, the
// channels advertised (live_channels.h), then the messages of the channels it subscribed to.
// publish() is called by the detection thread and never waits: it leaves the stack for the live
// thread, replacing one not yet taken (counted as skipped), and returns at once when no viewer
// subscribed to anything. The live thread encodes each subscribed channel once per stack and
// queues the bytes to every viewer that wants them; a viewer with more than viewerQueueBytes
// queued (slow, or its network) is disconnected (counted), the others go on.

#include <cstdint>
#include <functional>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fusedet/daemon/live/listen_address.h"
#include "fusedet/daemon/live/live_channels.h"
#include "fusedet/daemon/pipeline.h"

namespace fusedet::daemon::live {

struct LiveLimits {
  int maxViewers = 8;
  std::size_t viewerQueueBytes = 16u << 20;
};

struct LiveCounters {
  std::size_t viewers = 0;           // connected now
  std::uint64_t accepted = 0;        // viewers that completed the handshake
  std::uint64_t refused = 0;         // over max_viewers, or without the subprotocol
  std::uint64_t droppedSlow = 0;     // over viewer_queue_bytes
  std::uint64_t disconnected = 0;    // closed by the viewer (or a socket error)
  std::uint64_t pages = 0;           // HTTP files served
  std::uint64_t notFound = 0;        // HTTP requests for anything else
  std::uint64_t stacks = 0;          // stacks encoded for viewers
  std::uint64_t stacksSkipped = 0;   // replaced before the live thread took them
  std::uint64_t messages = 0;        // messages queued to viewers
  std::uint64_t bytes = 0;           // their bytes
  double lastEncodeMs = 0;           // encoding the last stack's subscribed channels
  std::vector<std::uint64_t> encoded;  // messages encoded per channel (index: channel id - 1)
};

class LiveServer {
 public:
  // Binds `address` (throws std::runtime_error naming it and the reason). status: the status
  // reply, for the /status channel (called on the live thread).
  LiveServer(const ListenAddress& address, LiveLimits limits, LiveChannels channels, std::function<nlohmann::json()> status);
  ~LiveServer();
  LiveServer(const LiveServer&) = delete;
  LiveServer& operator=(const LiveServer&) = delete;

  void start();
  // Closes the listener and every connection, joins the thread.
  void stop();

  void publish(std::shared_ptr<const StackResult> result);

  LiveCounters counters() const;
  // What it is bound to, the port the kernel chose for port 0 included.
  ListenAddress address() const;
  // The advertised channels (LiveChannels::channels()).
  const std::vector<Channel>& channels() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fusedet::daemon::live
