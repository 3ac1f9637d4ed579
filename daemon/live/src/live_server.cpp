// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/live/live_server.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>

#include <boost/asio/io_context.hpp>
#include <boost/asio/ip/tcp.hpp>
#include <boost/asio/local/stream_protocol.hpp>
#include <boost/asio/post.hpp>
#include <boost/asio/steady_timer.hpp>
#include <boost/beast/websocket.hpp>
#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <spdlog/spdlog.h>
#include <stdexcept>
#include <thread>

#include "fusedet/daemon/thread_info.h"
#include "http_session.h"
#include "live_state.h"
#include "viewer_session.h"

namespace fusedet::daemon::live {

namespace net = boost::asio;
namespace beast = boost::beast;

namespace {
constexpr auto kStatusPeriod = std::chrono::seconds(1);
}  // namespace

class LiveServer::Impl {
 public:
  Impl(const ListenAddress& address, LiveLimits limits, LiveChannels channels, std::function<nlohmann::json()> status)
      : address_(address), state_(std::move(channels), limits), status_(std::move(status)), acceptor_(io_), timer_(io_) {
    bind();
  }

  ~Impl() {
    stop();
    state_.viewers.clear();  // before io_: their sockets belong to it
  }

  void start() {
    accept();
    tick();
    thread_ = std::thread([this] {
      nameThisThread("fd-live");
      io_.run();
    });
  }

  void stop() {
    if (!thread_.joinable()) return;
    net::post(io_, [this] {
      beast::error_code ignored;
      acceptor_.close(ignored);
      timer_.cancel();
      const auto viewers = state_.viewers;  // close() removes each from the list
      for (const auto& v : viewers) v->close();
      io_.stop();
    });
    thread_.join();
    if (address_.kind == ListenAddress::Kind::kUnix) std::filesystem::remove(address_.path);
  }

  void publish(std::shared_ptr<const StackResult> result) {
    if (!state_.anySubscription.load(std::memory_order_relaxed)) return;
    {
      std::lock_guard lock(pendingMutex_);
      const bool waiting = pending_ != nullptr;
      pending_ = std::move(result);
      if (waiting) {
        state_.count([](LiveCounters& c) { ++c.stacksSkipped; });
        return;  // the live thread has not taken the last one yet: it will take this one instead
      }
    }
    net::post(io_, [this] { encodePending(); });
  }

  LiveCounters counters() const { return state_.snapshot(); }
  ListenAddress address() const { return address_; }
  const std::vector<Channel>& channels() const { return state_.channels.channels(); }

 private:
  void bind() {
    try {
      Protocol::endpoint endpoint;
      if (address_.kind == ListenAddress::Kind::kUnix) {
        std::error_code ec;
        if (std::filesystem::is_socket(address_.path, ec)) std::filesystem::remove(address_.path, ec);  // a previous run's
        endpoint = net::local::stream_protocol::endpoint(address_.path);
      } else {
        endpoint = net::ip::tcp::endpoint(net::ip::make_address(address_.host), address_.port);
      }
      acceptor_.open(endpoint.protocol());
      if (address_.kind == ListenAddress::Kind::kTcp) acceptor_.set_option(net::socket_base::reuse_address(true));
      acceptor_.bind(endpoint);
      acceptor_.listen(net::socket_base::max_listen_connections);
      if (address_.kind == ListenAddress::Kind::kTcp) {
        sockaddr_storage bound{};
        socklen_t size = sizeof bound;
        if (::getsockname(acceptor_.native_handle(), reinterpret_cast<sockaddr*>(&bound), &size) == 0)
          address_.port = ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<sockaddr_in6*>(&bound)->sin6_port
                                                            : reinterpret_cast<sockaddr_in*>(&bound)->sin_port);
      }
    } catch (const boost::system::system_error& e) {
      throw std::runtime_error("live.listen " + address_.text() + ": " + e.code().message() +
                               (e.code() == boost::system::errc::address_family_not_supported
                                    ? " (under systemd: the live-view drop-in allows the address family, docs/live-view.md)"
                                    : ""));
    }
    spdlog::info("live view on {}{}", address_.text(), address_.loopback() ? "" : " (not loopback: reachable from the network)");
  }

  void accept() {
    acceptor_.async_accept([this](beast::error_code ec, Protocol::socket socket) {
      if (ec == net::error::operation_aborted) return;
      if (!ec) std::make_shared<HttpSession>(Stream(std::move(socket)), state_)->start();
      else spdlog::warn("live: accept: {}", ec.message());
      accept();
    });
  }

  // The stack publish() left: each channel some viewer subscribed to, encoded once, to each of them.
  void encodePending() {
    std::shared_ptr<const StackResult> r;
    {
      std::lock_guard lock(pendingMutex_);
      r = std::move(pending_);
    }
    if (!r) return;
    const auto t0 = std::chrono::steady_clock::now();
    const auto viewers = state_.viewers;  // a viewer dropped while sending leaves the list
    const std::uint64_t stamp = static_cast<std::uint64_t>(std::max<std::int64_t>(0, r->frameStamp.ns));
    bool any = false;
    for (const Channel& c : state_.channels.channels()) {
      bool wanted = false;
      for (const auto& v : viewers) wanted = wanted || !v->subscriptionsOf(c.id).empty();
      if (!wanted) continue;
      any = true;
      auto payload = state_.channels.encode(c.id, *r);
      if (!payload) continue;
      state_.count([&](LiveCounters& n) { ++n.encoded[c.id - 1]; });
      const auto shared = std::make_shared<const std::vector<std::uint8_t>>(std::move(*payload));
      for (const auto& v : viewers) v->send(c.id, stamp, shared);
    }
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    state_.count([&](LiveCounters& c) {
      ++c.stacks;
      c.lastEncodeMs = ms;
    });
    updateInterest(any);
  }

  void updateInterest(bool known = false) {
    bool any = known;
    for (const auto& v : state_.viewers) any = any || v->subscribedToAnything();
    state_.anySubscription = any;
  }

  // Once a second: /status to its subscribers; who subscribes to anything (publish's shortcut).
  void tick() {
    timer_.expires_after(kStatusPeriod);
    timer_.async_wait([this](beast::error_code ec) {
      if (ec) return;
      updateInterest();
      const std::uint32_t id = state_.channels.statusChannel();
      const auto viewers = state_.viewers;
      bool wanted = false;
      for (const auto& v : viewers) wanted = wanted || !v->subscriptionsOf(id).empty();
      if (wanted && status_) {
        const Stamp now = Stamp::now();
        const auto payload = std::make_shared<const std::vector<std::uint8_t>>(state_.channels.encodeStatus(status_(), now));
        state_.count([&](LiveCounters& n) { ++n.encoded[id - 1]; });
        for (const auto& v : viewers) v->send(id, static_cast<std::uint64_t>(now.ns), payload);
      }
      tick();
    });
  }

  ListenAddress address_;
  LiveState state_;
  std::function<nlohmann::json()> status_;
  net::io_context io_{1};
  net::basic_socket_acceptor<Protocol> acceptor_;
  net::steady_timer timer_;
  std::thread thread_;
  std::mutex pendingMutex_;
  std::shared_ptr<const StackResult> pending_;
};

LiveServer::LiveServer(const ListenAddress& address, LiveLimits limits, LiveChannels channels, std::function<nlohmann::json()> status)
    : impl_(std::make_unique<Impl>(address, limits, std::move(channels), std::move(status))) {}
LiveServer::~LiveServer() { impl_->stop(); }
void LiveServer::start() { impl_->start(); }
void LiveServer::stop() { impl_->stop(); }
void LiveServer::publish(std::shared_ptr<const StackResult> result) { impl_->publish(std::move(result)); }
LiveCounters LiveServer::counters() const { return impl_->counters(); }
ListenAddress LiveServer::address() const { return impl_->address(); }
const std::vector<Channel>& LiveServer::channels() const { return impl_->channels(); }

}  // namespace fusedet::daemon::live
