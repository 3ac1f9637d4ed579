// SPDX-License-Identifier: Apache-2.0
#pragma once
// The socket protocol's messages (docs/protocol.md): one JSON object per line in each direction.
// Requests carry "cmd" (hello | subscribe | unsubscribe | latest | status) and an optional "id"
// that the reply echoes; replies and pushed messages carry "type".

#include <nlohmann/json.hpp>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "fusedet/daemon/pipeline.h"

namespace fusedet::daemon {

inline constexpr int kProtocolVersion = 1;

struct Request {
  enum class Command { kHello, kSubscribe, kUnsubscribe, kLatest, kStatus } command = Command::kHello;
  std::set<std::string> classes;  // subscribe: empty = every class
  // subscribe / unsubscribe: "detections" (default for subscribe) or "tracks"; unsubscribe
  // without a stream ends both.
  std::string stream;
  nlohmann::json id;              // echoed in the reply when present (null = absent)
};

// Parses one request line (without its newline). On failure returns nothing and sets `error` to
// a short reason ("not JSON: ...", "missing \"cmd\"", "unknown cmd 'x'", ...) and `id` (when
// given) to the request's "id" if it was a JSON object with one, so the error line carries it.
std::optional<Request> parseRequest(std::string_view line, std::string& error, nlohmann::json* id = nullptr);

// {"type":"detections", ...} for one stack; only the detections of `classes` (empty = all).
nlohmann::json resultToJson(const StackResult& result, const std::set<std::string>& classes = {},
                            const char* type = "detections");

// {"type":"tracks", ...} for one stack: every live track (tentative, confirmed, coasting) of
// `classes` (empty = all).
nlohmann::json tracksToJson(const StackResult& result, const std::set<std::string>& classes = {});

// {"type":"error","error":reason} (+ "id" when not null), as a line with its newline.
std::string errorLine(const std::string& reason, const nlohmann::json& id = nullptr);
// A JSON value as one line with its newline (invalid UTF-8 replaced, never throws).
std::string toLine(const nlohmann::json& message);

}  // namespace fusedet::daemon
