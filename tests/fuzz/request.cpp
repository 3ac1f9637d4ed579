// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: one request line from a socket client (docs/protocol.md) as the server takes
// it: parsed, and the reply to a bad one encoded with the request's id. Only a clean return is
// allowed: bad input is an error line, never an exception or a crash.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "fusedet/daemon/protocol.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::daemon;
  const std::string_view line(reinterpret_cast<const char*>(data), size);
  std::string error;
  nlohmann::json id;
  if (const auto request = parseRequest(line, error, &id)) {
    if (!request->id.is_null()) (void)toLine({{"type", "status"}, {"id", request->id}});
  } else {
    (void)errorLine(error, id);
  }
  return 0;
}
