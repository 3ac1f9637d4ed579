// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/base64.h"

#include <array>

namespace fusedet::drivers::logs {

namespace {
constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";

std::array<std::int8_t, 256> makeDecodeTable() {
  std::array<std::int8_t, 256> t{};
  t.fill(-1);
  for (int i = 0; i < 64; ++i) t[static_cast<unsigned char>(kAlphabet[i])] = static_cast<std::int8_t>(i);
  return t;
}
}  // namespace

std::string base64Encode(std::span<const std::uint8_t> bytes) {
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 3 <= bytes.size(); i += 3) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (std::uint32_t{bytes[i + 1]} << 8) | bytes[i + 2];
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += kAlphabet[(v >> 6) & 63];
    out += kAlphabet[v & 63];
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    const std::uint32_t v = (std::uint32_t{bytes[i]} << 16) | (rest == 2 ? std::uint32_t{bytes[i + 1]} << 8 : 0);
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::optional<std::vector<std::uint8_t>> base64Decode(std::string_view text) {
  static const std::array<std::int8_t, 256> table = makeDecodeTable();
  if (text.size() % 4 != 0) return std::nullopt;
  // Sized once and written through a pointer: a camera frame is ~1.2 MB of text, decoded on
  // every replay (push_back per byte cost most of the time).
  std::vector<std::uint8_t> out(text.size() / 4 * 3);
  std::uint8_t* o = out.data();
  const auto* t = reinterpret_cast<const unsigned char*>(text.data());
  const std::size_t full = text.empty() ? 0 : text.size() - 4;  // groups before the last one
  for (std::size_t i = 0; i < full; i += 4, o += 3) {
    const int a = table[t[i]], b = table[t[i + 1]], c = table[t[i + 2]], d = table[t[i + 3]];
    if ((a | b | c | d) < 0) return std::nullopt;  // any character outside the alphabet (also '=')
    const std::uint32_t v = static_cast<std::uint32_t>(a) << 18 | static_cast<std::uint32_t>(b) << 12 |
                            static_cast<std::uint32_t>(c) << 6 | static_cast<std::uint32_t>(d);
    o[0] = static_cast<std::uint8_t>(v >> 16);
    o[1] = static_cast<std::uint8_t>(v >> 8);
    o[2] = static_cast<std::uint8_t>(v);
  }
  if (text.empty()) return out;
  // The last group may end in padding.
  const std::size_t i = full;
  const int pad = (text[i + 3] == '=') + (text[i + 2] == '=');
  if (pad == 1 && text[i + 2] == '=') return std::nullopt;  // "x=y=" is not padding
  std::uint32_t v = 0;
  for (int k = 0; k < 4 - pad; ++k) {
    const std::int8_t d = table[t[i + static_cast<std::size_t>(k)]];
    if (d < 0) return std::nullopt;
    v |= static_cast<std::uint32_t>(d) << (18 - 6 * k);
  }
  o[0] = static_cast<std::uint8_t>(v >> 16);
  if (pad < 2) o[1] = static_cast<std::uint8_t>(v >> 8);
  if (pad < 1) o[2] = static_cast<std::uint8_t>(v);
  out.resize(out.size() - static_cast<std::size_t>(pad));
  return out;
}

}  // namespace fusedet::drivers::logs
