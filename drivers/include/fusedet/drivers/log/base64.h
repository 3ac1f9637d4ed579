// SPDX-License-Identifier: Apache-2.0
#pragma once
// Base64 (RFC 4648, standard alphabet, padded): how JSON-encoded MCAP messages carry bytes
// (the Foxglove convention for `bytes` fields).

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::drivers::logs {

std::string base64Encode(std::span<const std::uint8_t> bytes);
// Nothing when the text is not canonical padded base64 (wrong length, bad character, bad padding).
std::optional<std::vector<std::uint8_t>> base64Decode(std::string_view text);

}  // namespace fusedet::drivers::logs
