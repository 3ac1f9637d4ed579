// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/live/foxglove_protocol.h"

#include <nlohmann/json.hpp>
#include <optional>

namespace fusedet::daemon::live {

using nlohmann::json;

namespace {
std::string dump(const json& j) { return j.dump(-1, ' ', false, json::error_handler_t::replace); }
}  // namespace

std::string serverInfoMessage(const std::string& name, const std::string& sessionId) {
  return dump({{"op", "serverInfo"},
               {"name", name},
               {"capabilities", json::array()},
               {"supportedEncodings", json::array()},
               {"metadata", json::object()},
               {"sessionId", sessionId}});
}

std::string advertiseMessage(const std::vector<Channel>& channels) {
  json list = json::array();
  for (const Channel& c : channels)
    list.push_back({{"id", c.id}, {"topic", c.topic}, {"encoding", "json"}, {"schemaName", c.schemaName},
                    {"schema", c.schema}, {"schemaEncoding", "jsonschema"}});
  return dump({{"op", "advertise"}, {"channels", list}});
}

std::string statusMessage(int level, const std::string& message) {
  return dump({{"op", "status"}, {"level", level}, {"message", message}});
}

ClientOp parseClientOp(std::string_view text) {
  const json j = json::parse(text.begin(), text.end(), nullptr, false);
  if (j.is_discarded() || !j.is_object()) return Unknown{"not a JSON object"};
  const auto op = j.find("op");
  if (op == j.end() || !op->is_string()) return Unknown{"no \"op\""};
  const std::string name = op->get<std::string>();
  auto id = [](const json& v) -> std::optional<std::uint32_t> {
    if (!v.is_number_unsigned() || v.get<std::uint64_t>() > 0xFFFFFFFFu) return std::nullopt;
    return static_cast<std::uint32_t>(v.get<std::uint64_t>());
  };
  if (name == "subscribe") {
    const auto list = j.find("subscriptions");
    if (list == j.end() || !list->is_array()) return Unknown{"subscribe: no \"subscriptions\" array"};
    Subscribe s;
    for (const json& e : *list) {
      if (!e.is_object() || !e.contains("id") || !e.contains("channelId")) return Unknown{"subscribe: an entry without id and channelId"};
      const auto sub = id(e["id"]), channel = id(e["channelId"]);
      if (!sub || !channel) return Unknown{"subscribe: id and channelId must be unsigned 32-bit integers"};
      s.subscriptions.emplace_back(*sub, *channel);
    }
    return s;
  }
  if (name == "unsubscribe") {
    const auto list = j.find("subscriptionIds");
    if (list == j.end() || !list->is_array()) return Unknown{"unsubscribe: no \"subscriptionIds\" array"};
    Unsubscribe u;
    for (const json& e : *list) {
      const auto sub = id(e);
      if (!sub) return Unknown{"unsubscribe: subscription ids must be unsigned 32-bit integers"};
      u.subscriptionIds.push_back(*sub);
    }
    return u;
  }
  return Unknown{"operation '" + name + "' is not supported by fusedetd (it only sends: subscribe and unsubscribe)"};
}

std::array<std::uint8_t, kMessageHeaderBytes> messageDataHeader(std::uint32_t subscriptionId, std::uint64_t timestampNs) {
  std::array<std::uint8_t, kMessageHeaderBytes> h{};
  h[0] = 0x01;
  for (int i = 0; i < 4; ++i) h[static_cast<std::size_t>(1 + i)] = static_cast<std::uint8_t>(subscriptionId >> (8 * i));
  for (int i = 0; i < 8; ++i) h[static_cast<std::size_t>(5 + i)] = static_cast<std::uint8_t>(timestampNs >> (8 * i));
  return h;
}

}  // namespace fusedet::daemon::live
