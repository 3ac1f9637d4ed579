// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/live/listen_address.h"

#include <arpa/inet.h>

#include <charconv>
#include <stdexcept>

namespace fusedet::daemon::live {
namespace {

std::uint16_t parsePort(const std::string& text, const std::string& whole) {
  unsigned value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || value > 65535)
    throw std::invalid_argument("'" + whole + "': the port must be a number from 0 to 65535");
  return static_cast<std::uint16_t>(value);
}

}  // namespace

bool ListenAddress::loopback() const {
  if (kind == Kind::kUnix) return true;
  in_addr v4{};
  if (::inet_pton(AF_INET, host.c_str(), &v4) == 1) return (ntohl(v4.s_addr) >> 24) == 127;
  return host == "::1";
}

std::string ListenAddress::text() const {
  if (kind == Kind::kUnix) return "unix:" + path;
  const bool v6 = host.find(':') != std::string::npos;
  return (v6 ? "[" + host + "]" : host) + ":" + std::to_string(port);
}

std::optional<ListenAddress> parseListenAddress(const std::string& text) {
  if (text.empty()) return std::nullopt;
  ListenAddress a;
  if (text.rfind("unix:", 0) == 0) {
    a.kind = ListenAddress::Kind::kUnix;
    a.path = text.substr(5);
    if (a.path.empty() || a.path[0] != '/') throw std::invalid_argument("'" + text + "': a Unix socket needs an absolute path (unix:/run/...)");
    if (a.path.size() >= 108) throw std::invalid_argument("'" + text + "': the socket path is longer than 107 bytes");
    return a;
  }
  const auto colon = text.rfind(':');
  if (colon == std::string::npos) {
    a.host = "127.0.0.1";
    a.port = parsePort(text, text);
    return a;
  }
  std::string host = text.substr(0, colon);
  if (host.size() >= 2 && host.front() == '[' && host.back() == ']') host = host.substr(1, host.size() - 2);
  else if (host.find(':') != std::string::npos) throw std::invalid_argument("'" + text + "': write an IPv6 address in brackets ([::1]:8765)");
  in_addr v4{};
  in6_addr v6{};
  if (::inet_pton(AF_INET, host.c_str(), &v4) != 1 && ::inet_pton(AF_INET6, host.c_str(), &v6) != 1)
    throw std::invalid_argument("'" + text + "': '" + host + "' is not an IP address (no host names: the address is bound as written)");
  a.host = host;
  a.port = parsePort(text.substr(colon + 1), text);
  return a;
}

}  // namespace fusedet::daemon::live
