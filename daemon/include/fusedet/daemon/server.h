// SPDX-License-Identifier: Apache-2.0
#pragma once
// Server: the Unix stream socket clients talk NDJSON on (docs/protocol.md), one epoll thread.
// publish() is called by the detection thread and only queues (never blocks); each client has a
// bounded queue of outgoing lines, and a client whose queue overflows (slow or silent) is
// dropped without delaying anyone else. Requests longer than the limit, or not JSON, get an error
// line; the connection stays usable.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "fusedet/daemon/pipeline.h"
#include "fusedet/daemon/stats.h"
#include "fusedet/drivers/unique_fd.h"

namespace fusedet::daemon {

struct ServerLimits {
  // Groups whose members may talk (socket.allow_groups: name, gid); empty = whoever can open the
  // socket file. Root and the daemon's own user are always allowed. Checked on the peer's
  // credentials (SO_PEERCRED) and supplementary groups (/proc/PID/status) at connect.
  std::vector<std::pair<std::string, unsigned>> allowGroups;
  int maxClients = 16;
  std::size_t maxRequestBytes = 4096;  // one request line, without its newline
  std::size_t clientQueue = 256;       // lines queued for one client before it is dropped
  // Kernel send buffer of each client connection (SO_SNDBUF; the kernel doubles it, minimum
  // ~4.6 KB); 0 = the system default (net.core.wmem_default, ~200 KB = ~170 lines). Lines in it
  // are out of the server's queue: a client is dropped after buffer + clientQueue lines unread.
  int clientSendBuffer = 0;
};

struct ServerCounters {
  std::size_t clients = 0;           // connected now
  std::uint64_t accepted = 0;
  std::uint64_t refused = 0;         // over max_clients
  std::uint64_t refusedNotAllowed = 0;  // in none of socket.allow_groups
  std::uint64_t refusedNoFd = 0;     // the daemon was out of file descriptors (EMFILE, ENFILE)
  std::uint64_t droppedSlow = 0;     // queue overflow: slow or silent clients
  std::uint64_t disconnected = 0;    // closed by the client (or a socket error)
  std::uint64_t badRequests = 0;     // not JSON, unknown cmd, ...
  std::uint64_t oversized = 0;       // request lines over the limit
  std::uint64_t linesSent = 0;       // lines queued to clients
  std::uint64_t results = 0;         // stack results published
};

// A connected client as the kernel tells it (SO_PEERCRED at connect).
struct Peer {
  std::uint64_t client = 0;  // the server's number for the connection (in its log lines)
  int pid = 0;
  unsigned uid = 0, gid = 0;
  bool subscribed = false;
};

class Server {
 public:
  struct Handlers {
    std::function<nlohmann::json()> hello;   // the hello reply (versions, classes)
    std::function<nlohmann::json()> status;  // the status reply
  };

  // Takes a listening, bound Unix stream socket (made non-blocking here).
  Server(drivers::UniqueFd listener, ServerLimits limits, Handlers handlers);
  ~Server();
  Server(const Server&) = delete;
  Server& operator=(const Server&) = delete;

  void start();
  // Stops accepting, sends what is queued until `deadline`, closes every client, joins.
  void stop(std::chrono::steady_clock::time_point deadline);

  // Queues one stack's detections for every subscribed client; called from the detection thread.
  void publish(std::shared_ptr<const StackResult> result);
  void setLimits(const ServerLimits& limits);

  ServerCounters counters() const;
  // The clients connected now, oldest first.
  std::vector<Peer> peers() const;
  // Sensor stamp -> line handed to the clients' sockets, last 1024 stacks.
  LatencySummary latency() const { return latency_.summary(); }
  std::int64_t beatNs() const { return beat_.load(); }

 private:
  struct Client;
  void run();
  void accept();
  bool refuseWithoutDescriptor(int err);
  void pauseListener();
  void readFrom(Client& c);
  void handleLine(Client& c, std::string_view line);
  void queue(Client& c, std::shared_ptr<const std::string> line);
  void flush(Client& c);
  void dispatch();
  void drop(Client& c, bool slow);
  void updateInterest(Client& c);
  void updatePeers();

  drivers::UniqueFd listener_, epoll_, wake_;
  // Out of descriptors, a pending connection keeps the listener readable: epoll would return at
  // once, forever (a spinning server). The spare (/dev/null) is given up for a moment to take the
  // connection, tell the client why and close it; without it the listener pauses 100 ms.
  drivers::UniqueFd spare_;
  std::optional<std::chrono::steady_clock::time_point> listenerPausedUntil_;  // server thread only
  std::chrono::steady_clock::time_point lastNoFdWarning_;                     // server thread only
  Handlers handlers_;
  std::thread thread_;
  std::atomic<bool> stopping_{false};
  std::chrono::steady_clock::time_point deadline_;
  std::atomic<std::int64_t> beat_{0};

  mutable std::mutex mutex_;  // guards limits_, pending_, latest_, counters_, peers_
  ServerLimits limits_;
  std::vector<std::shared_ptr<const StackResult>> pending_;
  std::shared_ptr<const StackResult> latest_;
  ServerCounters counters_;
  std::vector<Peer> peers_;

  std::vector<std::unique_ptr<Client>> clients_;  // server thread only
  std::uint64_t nextKey_ = 2;                    // server thread only; 0, 1: listener, wake
  LatencyRecorder latency_;
};

// Who may open the socket file: its mode and group (socket.mode, socket.group).
struct SocketAccess {
  unsigned mode = 0660;
  std::optional<unsigned> group;  // gid; nothing = the daemon's own group
};

// Binds and listens on `path` (a stale socket file is replaced; a live one is an error) with
// `access`'s mode and group. Refuses a path in a world-writable directory that the daemon's user
// does not own (another local user could replace or pre-create the socket there). Throws
// std::system_error naming the path and why.
drivers::UniqueFd bindUnixSocket(const std::string& path, const SocketAccess& access = {});
// For a socket passed by systemd (socket activation): refuses it when its file grants more than
// `access.mode` or belongs to another group than `access.group` (when given). Throws
// std::runtime_error saying which.
void checkPassedSocket(int fd, const SocketAccess& access);

}  // namespace fusedet::daemon
