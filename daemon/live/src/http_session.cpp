// SPDX-License-Identifier: Apache-2.0
#include "http_session.h"

#include <boost/beast/http.hpp>
#include <boost/beast/websocket/rfc6455.hpp>
#include <chrono>

#include "fusedet/daemon/live/foxglove_protocol.h"
#include "viewer_session.h"
#include "web_files.h"

namespace fusedet::daemon::live {

namespace beast = boost::beast;
namespace http = beast::http;
namespace websocket = beast::websocket;

namespace {
std::string_view view(beast::string_view s) { return {s.data(), s.size()}; }
constexpr auto kRequestTimeout = std::chrono::seconds(30);
constexpr std::uint32_t kMaxRequestBytes = 16 * 1024;

// The Sec-WebSocket-Protocol list names the Foxglove subprotocol.
bool asksForFoxglove(std::string_view list) {
  for (std::size_t start = 0; start <= list.size();) {
    std::size_t end = list.find(',', start);
    if (end == std::string_view::npos) end = list.size();
    std::string_view item = list.substr(start, end - start);
    while (!item.empty() && item.front() == ' ') item.remove_prefix(1);
    while (!item.empty() && item.back() == ' ') item.remove_suffix(1);
    if (item == kSubprotocol) return true;
    start = end + 1;
  }
  return false;
}
}  // namespace

void HttpSession::read() {
  request_ = {};
  stream_.expires_after(kRequestTimeout);
  auto parser = std::make_shared<http::request_parser<http::string_body>>();
  parser->header_limit(kMaxRequestBytes);
  parser->body_limit(kMaxRequestBytes);
  http::async_read(stream_, buffer_, *parser, [self = shared_from_this(), parser](beast::error_code ec, std::size_t) {
    if (ec) {
      beast::error_code ignored;
      self->stream_.socket().close(ignored);
      return;
    }
    self->request_ = parser->release();
    self->onRequest();
  });
}

void HttpSession::onRequest() {
  if (websocket::is_upgrade(request_)) {
    if (static_cast<int>(state_.viewers.size()) >= state_.limits.maxViewers) {
      state_.count([](LiveCounters& c) { ++c.refused; });
      respond(http::status::service_unavailable, "text/plain", "fusedetd: live.max_viewers viewers are connected\n", false);
      return;
    }
    if (!asksForFoxglove(view(request_[http::field::sec_websocket_protocol]))) {
      state_.count([](LiveCounters& c) { ++c.refused; });
      respond(http::status::bad_request, "text/plain", std::string("fusedetd: ask for the WebSocket subprotocol ") + kSubprotocol + "\n", false);
      return;
    }
    stream_.expires_never();
    std::make_shared<ViewerSession>(std::move(stream_), state_)->start(std::move(request_));
    return;
  }
  const bool keepAlive = request_.keep_alive();
  if (request_.method() != http::verb::get && request_.method() != http::verb::head) {
    state_.count([](LiveCounters& c) { ++c.notFound; });
    respond(http::status::method_not_allowed, "text/plain", "fusedetd: GET or HEAD only\n", keepAlive);
    return;
  }
  const WebFile* file = webFile(view(request_.target()));
  if (!file) {
    state_.count([](LiveCounters& c) { ++c.notFound; });
    respond(http::status::not_found, "text/plain", "fusedetd: no such file\n", keepAlive);
    return;
  }
  state_.count([](LiveCounters& c) { ++c.pages; });
  respond(http::status::ok, file->contentType, std::string(file->body), keepAlive);
}

void HttpSession::respond(http::status status, std::string_view contentType, std::string body, bool keepAlive) {
  response_ = std::make_shared<http::response<http::string_body>>(status, request_.version());
  response_->set(http::field::server, "fusedetd");
  response_->set(http::field::content_type, beast::string_view(contentType.data(), contentType.size()));
  response_->set(http::field::cache_control, "no-store");
  response_->set("X-Content-Type-Options", "nosniff");
  response_->keep_alive(keepAlive);
  const bool head = request_.method() == http::verb::head;
  response_->body() = std::move(body);
  response_->prepare_payload();
  if (head) response_->body().clear();  // Content-Length stays the file's
  stream_.expires_after(kRequestTimeout);
  http::async_write(stream_, *response_, [self = shared_from_this(), keepAlive](beast::error_code ec, std::size_t) {
    if (ec || !keepAlive) {
      beast::error_code ignored;
      self->stream_.socket().shutdown(Protocol::socket::shutdown_send, ignored);
      self->stream_.socket().close(ignored);
      return;
    }
    self->read();
  });
}

}  // namespace fusedet::daemon::live
