// SPDX-License-Identifier: Apache-2.0
#pragma once
// SdoClient: the client side of one node's default SDO channel (request 0x600+n, response
// 0x580+n). Asynchronous, so the master's single loop keeps producing SYNC and consuming PDOs
// while a transfer is under way: transfers queue up and run one at a time; onFrame() feeds
// responses, poll() enforces the timeout (then an abort 0x05040000 is sent to the server).
// Expedited download (1..4 bytes), expedited and segmented upload. A server abort completes
// the transfer with an Error in sdoAbortCategory() whose value is the abort code.

#include <chrono>
#include <cstdint>
#include <deque>
#include <functional>
#include <system_error>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/canopen/can_bus.h"

namespace fusedet::drivers::canopen {

const std::error_category& sdoAbortCategory();  // message(code) = abortCodeText(code)

struct SdoCounters {
  std::uint64_t transfers = 0;   // completed successfully
  std::uint64_t aborts = 0;      // aborted by the server
  std::uint64_t timeouts = 0;    // no (or no fitting) response in time
  std::uint64_t sendErrors = 0;  // request could not be sent
};

class SdoClient {
 public:
  using Bytes = std::vector<std::uint8_t>;
  using Done = std::function<void(Result<Bytes>)>;  // download: empty bytes on success

  SdoClient(CanBus& bus, int node, std::chrono::milliseconds timeout = std::chrono::milliseconds(200))
      : bus_(bus), node_(node), timeout_(timeout) {}

  void download(std::uint16_t index, std::uint8_t sub, std::uint32_t value, int bytes, Done done);
  void upload(std::uint16_t index, std::uint8_t sub, Done done);

  // Feeds a received frame; true if it was this channel's response.
  bool onFrame(const CanFrame& f);
  void poll(Stamp now);
  // Completes every queued and running transfer with `why` (e.g. the node went silent).
  void cancelAll(const Error& why);
  bool idle() const { return queue_.empty(); }
  int node() const { return node_; }
  const SdoCounters& counters() const { return counters_; }
  // Largest segmented upload accepted (protects against a server that never sets "last").
  static constexpr std::size_t kMaxUpload = 4096;

 private:
  struct Transfer {
    bool upload = false;
    std::uint16_t index = 0;
    std::uint8_t sub = 0;
    std::uint32_t value = 0;
    int bytes = 0;
    Done done;
    bool started = false;
    bool segmented = false;
    bool toggle = false;
    Bytes data;
    Stamp deadline;
  };
  void startNext();
  void sendRequest(const CanFrame& f);
  void finish(Result<Bytes> r);
  Error abortError(std::uint32_t code, const Transfer& t) const;
  std::string what(const Transfer& t) const;  // "SDO upload 0x1008:00 node 5"

  CanBus& bus_;
  int node_;
  std::chrono::milliseconds timeout_;
  std::deque<Transfer> queue_;  // front = running
  SdoCounters counters_;
};

}  // namespace fusedet::drivers::canopen
