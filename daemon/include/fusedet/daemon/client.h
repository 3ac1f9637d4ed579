// SPDX-License-Identifier: Apache-2.0
#pragma once
// Client: the client side of the socket protocol (docs/protocol.md) - connect, send a request,
// read reply lines. Used by `fusedet query` and the tests.

#include <chrono>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>

#include "fusedet/drivers/unique_fd.h"

namespace fusedet::daemon {

class Client {
 public:
  // Throws std::system_error naming the path when it cannot connect.
  explicit Client(const std::string& socketPath);

  // Sends one line (a newline is appended). Throws std::system_error on a broken connection.
  void sendLine(const std::string& line);
  void send(const nlohmann::json& request) { sendLine(request.dump()); }
  // The next line without its newline; nothing on timeout or when the server closed the
  // connection (closed() tells which).
  std::optional<std::string> readLine(std::chrono::milliseconds timeout);
  // The next line parsed; throws std::runtime_error when the line is not JSON.
  std::optional<nlohmann::json> read(std::chrono::milliseconds timeout);
  bool closed() const { return closed_; }
  int fd() const { return fd_.get(); }

 private:
  drivers::UniqueFd fd_;
  std::string buffer_;
  bool closed_ = false;
};

}  // namespace fusedet::daemon
