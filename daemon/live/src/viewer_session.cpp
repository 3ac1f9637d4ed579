// SPDX-License-Identifier: Apache-2.0
#include "viewer_session.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <boost/beast/core/buffers_to_string.hpp>
#include <boost/beast/websocket.hpp>
#include <variant>

#include "fusedet/daemon/live/foxglove_protocol.h"

namespace fusedet::daemon::live {

namespace beast = boost::beast;
namespace http = beast::http;
namespace net = boost::asio;
namespace websocket = beast::websocket;

namespace {
constexpr std::size_t kMaxClientMessage = 64 * 1024;  // subscribe lists; fusedetd takes nothing larger
}  // namespace

ViewerSession::ViewerSession(Stream stream, LiveState& state) : ws_(std::move(stream)), state_(state) {}

void ViewerSession::start(http::request<http::string_body> request) {
  ws_.set_option(websocket::stream_base::timeout::suggested(beast::role_type::server));
  ws_.set_option(websocket::stream_base::decorator([](websocket::response_type& res) {
    res.set(http::field::server, "fusedetd");
    res.set(http::field::sec_websocket_protocol, kSubprotocol);
  }));
  ws_.read_message_max(kMaxClientMessage);
  ws_.async_accept(request, [self = shared_from_this()](beast::error_code ec) {
    if (ec) {
      self->closed_ = true;
      return;
    }
    self->open_ = true;
    self->number_ = self->state_.nextViewer++;
    self->state_.viewers.push_back(self);
    self->state_.count([](LiveCounters& c) {
      ++c.accepted;
      ++c.viewers;
    });
    spdlog::info("live: viewer {} connected", self->number_);
    self->sendText(serverInfoMessage("fusedetd", std::to_string(self->number_)));
    self->sendText(advertiseMessage(self->state_.channels.channels()));
    self->read();
  });
}

std::vector<std::uint32_t> ViewerSession::subscriptionsOf(std::uint32_t channel) const {
  std::vector<std::uint32_t> ids;
  for (const auto& [id, ch] : subscriptions_)
    if (ch == channel) ids.push_back(id);
  return ids;
}

void ViewerSession::send(std::uint32_t channel, std::uint64_t timestampNs, const std::shared_ptr<const std::vector<std::uint8_t>>& payload) {
  for (std::uint32_t id : subscriptionsOf(channel)) {
    Outgoing o;
    o.header = messageDataHeader(id, timestampNs);
    o.payload = payload;
    enqueue(std::move(o));
  }
}

void ViewerSession::sendText(std::string text) {
  Outgoing o;
  o.text = std::make_shared<const std::string>(std::move(text));
  enqueue(std::move(o));
}

void ViewerSession::enqueue(Outgoing out) {
  if (closed_) return;
  const std::size_t bytes = out.bytes();
  if (queued_ + bytes > state_.limits.viewerQueueBytes) {
    spdlog::warn("live: viewer {} dropped: {} bytes queued, over live.viewer_queue_bytes {}", number_, queued_ + bytes,
                 state_.limits.viewerQueueBytes);
    finish(true);
    return;
  }
  queued_ += bytes;
  state_.count([&](LiveCounters& c) {
    if (!out.text) ++c.messages;
    c.bytes += bytes;
  });
  out_.push_back(std::move(out));
  if (!writing_) writeNext();
}

void ViewerSession::writeNext() {
  if (closed_ || out_.empty()) {
    writing_ = false;
    return;
  }
  writing_ = true;
  const Outgoing& o = out_.front();  // stays in place until its write completes (deque)
  auto done = [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec || self->closed_) {
      self->finish(false);
      return;
    }
    self->queued_ -= self->out_.front().bytes();
    self->out_.pop_front();
    self->writeNext();
  };
  ws_.binary(!o.text);
  if (o.text) {
    ws_.async_write(net::buffer(*o.text), std::move(done));
  } else {
    const std::array<net::const_buffer, 2> frame{net::buffer(o.header), net::buffer(*o.payload)};
    ws_.async_write(frame, std::move(done));
  }
}

void ViewerSession::read() {
  ws_.async_read(in_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
    if (ec) {
      self->finish(false);
      return;
    }
    if (self->ws_.got_text()) self->onText(beast::buffers_to_string(self->in_.data()));
    self->in_.consume(self->in_.size());
    if (!self->closed_) self->read();
  });
}

void ViewerSession::onText(const std::string& text) {
  const ClientOp op = parseClientOp(text);
  if (const auto* s = std::get_if<Subscribe>(&op)) {
    const std::size_t channels = state_.channels.channels().size();
    for (const auto& [id, channel] : s->subscriptions) {
      if (channel == 0 || channel > channels) {
        sendText(statusMessage(1, "subscribe: no channel " + std::to_string(channel)));
        continue;
      }
      subscriptions_[id] = channel;
      state_.anySubscription = true;
    }
  } else if (const auto* u = std::get_if<Unsubscribe>(&op)) {
    for (std::uint32_t id : u->subscriptionIds) subscriptions_.erase(id);
  } else {
    sendText(statusMessage(1, std::get<Unknown>(op).why));
  }
}

void ViewerSession::finish(bool slow, bool counted) {
  if (closed_) return;
  closed_ = true;
  beast::error_code ec;
  beast::get_lowest_layer(ws_).socket().close(ec);  // pending reads and writes end with operation_aborted
  out_.clear();
  queued_ = 0;
  if (!open_) return;
  auto& v = state_.viewers;
  v.erase(std::remove_if(v.begin(), v.end(), [this](const auto& p) { return p.get() == this; }), v.end());
  state_.count([&](LiveCounters& c) {
    --c.viewers;
    if (slow) ++c.droppedSlow;
    else if (counted) ++c.disconnected;
  });
  spdlog::info("live: viewer {} {}", number_, slow ? "dropped (too slow)" : counted ? "disconnected" : "closed");
}

}  // namespace fusedet::daemon::live
