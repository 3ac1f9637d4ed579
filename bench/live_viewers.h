// SPDX-License-Identifier: Apache-2.0
#pragma once
// Viewers of fusedetd's live view for bench_daemon_latency: each a thread with a Boost.Beast
// WebSocket client (subprotocol foxglove.websocket.v1) that subscribes to every advertised
// channel and reads as fast as it can, counting messages and bytes - what a Foxglove app or the
// page costs the daemon, without their drawing.

#include <atomic>
#include <cstdint>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace fusedet::bench {

class LiveViewers {
 public:
  // Connects n viewers to HOST:PORT; throws std::runtime_error when one cannot connect.
  LiveViewers(const std::string& host, std::uint16_t port, int n);
  ~LiveViewers();
  LiveViewers(const LiveViewers&) = delete;
  LiveViewers& operator=(const LiveViewers&) = delete;

  // Disconnects every viewer and joins the threads.
  void stop();
  std::uint64_t messages() const;  // Message Data frames received, all viewers
  std::uint64_t bytes() const;
  int disconnected() const;  // viewers the server closed before stop()

 private:
  struct Viewer;
  std::vector<std::unique_ptr<Viewer>> viewers_;
  std::atomic<bool> stopping_{false};
};

}  // namespace fusedet::bench
