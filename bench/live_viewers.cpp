// SPDX-License-Identifier: Apache-2.0
#include "live_viewers.h"

#include <sys/socket.h>

#include <boost/asio/connect.hpp>
#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>
#include <stdexcept>

namespace fusedet::bench {

namespace net = boost::asio;
namespace beast = boost::beast;
namespace websocket = beast::websocket;

struct LiveViewers::Viewer {
  net::io_context io;
  websocket::stream<net::ip::tcp::socket> ws{io};
  std::thread thread;
  std::atomic<std::uint64_t> messages{0}, bytes{0};
  std::atomic<bool> closedByServer{false};
};

LiveViewers::LiveViewers(const std::string& host, std::uint16_t port, int n) {
  for (int i = 0; i < n; ++i) {
    auto v = std::make_unique<Viewer>();
    try {
      v->ws.next_layer().connect(net::ip::tcp::endpoint(net::ip::make_address(host), port));
      v->ws.set_option(websocket::stream_base::decorator(
          [](websocket::request_type& req) { req.set(beast::http::field::sec_websocket_protocol, "foxglove.websocket.v1"); }));
      v->ws.handshake(host + ":" + std::to_string(port), "/");
      // serverInfo, then advertise: subscribe to every channel.
      for (int text = 0; text < 2; ++text) {
        beast::flat_buffer b;
        v->ws.read(b);
        const auto j = nlohmann::json::parse(beast::buffers_to_string(b.data()));
        if (j.value("op", "") != "advertise") continue;
        nlohmann::json subs = nlohmann::json::array();
        for (const auto& c : j["channels"]) subs.push_back({{"id", c["id"]}, {"channelId", c["id"]}});
        v->ws.text(true);
        v->ws.write(net::buffer(nlohmann::json{{"op", "subscribe"}, {"subscriptions", subs}}.dump()));
      }
    } catch (const std::exception& e) {
      throw std::runtime_error("live viewer " + std::to_string(i) + ": " + e.what());
    }
    Viewer* raw = v.get();
    v->thread = std::thread([this, raw] {
      beast::flat_buffer b;
      beast::error_code ec;
      while (true) {
        raw->ws.read(b, ec);
        if (ec) {
          if (!stopping_) raw->closedByServer = true;
          return;
        }
        ++raw->messages;
        raw->bytes += b.size();
        b.consume(b.size());
      }
    });
    viewers_.push_back(std::move(v));
  }
}

LiveViewers::~LiveViewers() { stop(); }

void LiveViewers::stop() {
  stopping_ = true;
  for (auto& v : viewers_) ::shutdown(v->ws.next_layer().native_handle(), SHUT_RDWR);  // ends the blocking read
  for (auto& v : viewers_)
    if (v->thread.joinable()) v->thread.join();
}

std::uint64_t LiveViewers::messages() const {
  std::uint64_t n = 0;
  for (const auto& v : viewers_) n += v->messages;
  return n;
}

std::uint64_t LiveViewers::bytes() const {
  std::uint64_t n = 0;
  for (const auto& v : viewers_) n += v->bytes;
  return n;
}

int LiveViewers::disconnected() const {
  int n = 0;
  for (const auto& v : viewers_) n += v->closedByServer ? 1 : 0;
  return n;
}

}  // namespace fusedet::bench
