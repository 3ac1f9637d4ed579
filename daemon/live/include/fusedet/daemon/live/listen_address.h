// SPDX-License-Identifier: Apache-2.0
#pragma once
// live.listen as an address: where the live view listens (docs/live-view.md).
//   ""                 off (the default)
//   "8765"             TCP port 8765 on the loopback address 127.0.0.1
//   "HOST:PORT"        TCP on HOST, an IPv4 or IPv6 literal ("[::1]:8765"); a non-loopback host
//                      is the explicit "told otherwise" (every interface: "0.0.0.0:8765")
//   "unix:/PATH"       a Unix stream socket at the absolute PATH
// Port 0 asks the kernel for a free port (tests, the bench).

#include <cstdint>
#include <optional>
#include <string>

namespace fusedet::daemon::live {

struct ListenAddress {
  enum class Kind { kTcp, kUnix } kind = Kind::kTcp;
  std::string host;  // kTcp: the IP literal, without brackets
  std::uint16_t port = 0;
  std::string path;  // kUnix
  bool loopback() const;  // kTcp on 127.0.0.0/8 or ::1; a Unix socket counts as local too
  std::string text() const;  // as written in the config ("127.0.0.1:8765", "[::1]:8765", "unix:/run/x")
};

// Nothing for "" (off). Throws std::invalid_argument saying what is wrong with `text`.
std::optional<ListenAddress> parseListenAddress(const std::string& text);

}  // namespace fusedet::daemon::live
