// SPDX-License-Identifier: Apache-2.0
#pragma once
// Private: one Foxglove WebSocket viewer - the handshake (subprotocol foxglove.websocket.v1),
// serverInfo and advertise, its subscriptions, and its outgoing queue: one write at a time, the
// queued bytes counted; over the limit the viewer is disconnected (slow), never waited for.

#include <array>
#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <boost/beast/websocket/stream.hpp>
#include <deque>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "live_state.h"

namespace fusedet::daemon::live {

class ViewerSession : public std::enable_shared_from_this<ViewerSession> {
 public:
  ViewerSession(Stream stream, LiveState& state);

  // Completes the upgrade `request` asked for; on success the viewer joins state.viewers.
  void start(boost::beast::http::request<boost::beast::http::string_body> request);

  // Live thread: the subscription ids this viewer has on `channel` (empty: not subscribed).
  std::vector<std::uint32_t> subscriptionsOf(std::uint32_t channel) const;
  bool subscribedToAnything() const { return !subscriptions_.empty(); }
  // Queues one Message Data frame per subscription id.
  void send(std::uint32_t channel, std::uint64_t timestampNs, const std::shared_ptr<const std::vector<std::uint8_t>>& payload);
  // Disconnects (the server stopping).
  void close() { finish(false, false); }

 private:
  struct Outgoing {
    std::shared_ptr<const std::string> text;                    // a JSON text message, or
    std::array<std::uint8_t, 13> header{};                      // a Message Data frame: header + payload
    std::shared_ptr<const std::vector<std::uint8_t>> payload;
    std::size_t bytes() const { return text ? text->size() : header.size() + payload->size(); }
  };
  void sendText(std::string text);
  void enqueue(Outgoing out);
  void writeNext();
  void read();
  void onText(const std::string& text);
  // slow: dropped for its queue; counted: count the disconnect (not when the server closes it).
  void finish(bool slow, bool counted = true);

  boost::beast::websocket::stream<Stream> ws_;
  LiveState& state_;
  std::uint64_t number_ = 0;
  boost::beast::flat_buffer in_;
  std::deque<Outgoing> out_;
  std::size_t queued_ = 0;
  bool writing_ = false, open_ = false, closed_ = false;
  std::map<std::uint32_t, std::uint32_t> subscriptions_;  // subscription id -> channel id
};

}  // namespace fusedet::daemon::live
