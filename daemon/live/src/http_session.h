// SPDX-License-Identifier: Apache-2.0
#pragma once
// Private: one HTTP connection to the live port - GET and HEAD of the page's files (web_files.h),
// keep-alive, 30 s to send a request; a WebSocket upgrade hands the connection to a
// ViewerSession (503 over max_viewers, 400 without the foxglove.websocket.v1 subprotocol).

#include <boost/beast/core/flat_buffer.hpp>
#include <boost/beast/http/message.hpp>
#include <boost/beast/http/string_body.hpp>
#include <memory>

#include "live_state.h"

namespace fusedet::daemon::live {

class HttpSession : public std::enable_shared_from_this<HttpSession> {
 public:
  HttpSession(Stream stream, LiveState& state) : stream_(std::move(stream)), state_(state) {}
  void start() { read(); }

 private:
  void read();
  void onRequest();
  void respond(boost::beast::http::status status, std::string_view contentType, std::string body, bool keepAlive);

  Stream stream_;
  LiveState& state_;
  boost::beast::flat_buffer buffer_;
  boost::beast::http::request<boost::beast::http::string_body> request_;
  std::shared_ptr<boost::beast::http::response<boost::beast::http::string_body>> response_;
};

}  // namespace fusedet::daemon::live
