// SPDX-License-Identifier: Apache-2.0
#pragma once
// The Foxglove WebSocket protocol, subprotocol "foxglove.websocket.v1" (the server side of the
// spec at github.com/foxglove/ws-protocol, docs/spec.md): the JSON text messages the server sends
// (serverInfo, advertise, status), the client operations it understands (subscribe,
// unsubscribe) and the binary Message Data frame header. Written from the spec; no Foxglove code.

#include <array>
#include <cstdint>
#include <string>
#include <string_view>
#include <utility>
#include <variant>
#include <vector>

namespace fusedet::daemon::live {

inline constexpr char kSubprotocol[] = "foxglove.websocket.v1";

// One advertised channel: messages JSON-encoded, their schema a JSON Schema.
struct Channel {
  std::uint32_t id = 0;
  std::string topic;
  std::string schemaName;  // "foxglove.CompressedImage", "fusedet.Status", ...
  std::string schema;      // the JSON Schema text
};

std::string serverInfoMessage(const std::string& name, const std::string& sessionId);
std::string advertiseMessage(const std::vector<Channel>& channels);
// level: 0 info, 1 warning, 2 error.
std::string statusMessage(int level, const std::string& message);

// What a client asked for. An operation the server does not support (publishing, services,
// parameters, ...) or malformed text is an Unknown carrying what to tell the client.
struct Subscribe {
  std::vector<std::pair<std::uint32_t, std::uint32_t>> subscriptions;  // (subscription id, channel id)
};
struct Unsubscribe {
  std::vector<std::uint32_t> subscriptionIds;
};
struct Unknown {
  std::string why;
};
using ClientOp = std::variant<Subscribe, Unsubscribe, Unknown>;
ClientOp parseClientOp(std::string_view text);

// Binary opcode 0x01 Message Data: opcode, subscription id (uint32 LE), receive timestamp (uint64 LE, ns)
// - the message's payload follows.
inline constexpr std::size_t kMessageHeaderBytes = 13;
std::array<std::uint8_t, kMessageHeaderBytes> messageDataHeader(std::uint32_t subscriptionId, std::uint64_t timestampNs);

}  // namespace fusedet::daemon::live
