// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: the LMS 291 serial byte stream - framing, resynchronisation after garbage,
// ACK/NAK bytes, CRC - as TelegramReader takes it from the port, cut into reads as the input's
// first byte says, and every telegram it yields decoded as the driver would (measured values,
// range + remission, status). Anything but a clean return is a finding.

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <span>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/telegram.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet::drivers::lms291;
  if (size == 0) return 0;
  const auto direction = static_cast<Direction>(data[0] % 3);
  const std::size_t chunk = 1 + data[0] / 3 % 64;  // bytes per read: 1 .. 64
  TelegramReader reader(direction);
  reader.setByteTime(data[0] & 1 ? 20'000 : 0);
  fusedet::Stamp t{1'000'000'000};
  auto drain = [&] {
    while (auto e = reader.next()) {
      if (e->kind != StreamEvent::Kind::kTelegram) continue;
      const std::span<const std::uint8_t> payload(e->telegram.data);
      switch (e->telegram.command) {
        case 0xB0: (void)decodeMeasuredValues(payload); break;
        case 0xF5: (void)decodeRangeRemission(payload); break;
        case 0xB1: (void)decodeStatus(payload); break;
        case 0xF4: (void)decodeConfig(payload); break;
        default: break;
      }
    }
  };
  for (std::size_t at = 1; at < size; at += chunk) {
    reader.feed(std::span<const std::uint8_t>(data + at, std::min(chunk, size - at)), t);
    t = fusedet::Stamp{t.ns + 1'000'000};
    drain();
  }
  reader.expirePending();  // a silence after the stream
  drain();
  return 0;
}
