// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/can_frame.h"

#include <algorithm>
#include <cstdio>

namespace fusedet::drivers::canopen {

CanFrame CanFrame::make(std::uint32_t id, std::initializer_list<std::uint8_t> bytes) {
  CanFrame f;
  f.id = id;
  f.extended = id > 0x7FF;
  f.len = static_cast<std::uint8_t>(std::min<std::size_t>(bytes.size(), 8));
  std::copy_n(bytes.begin(), f.len, f.data.begin());
  return f;
}

bool CanFrame::sameContent(const CanFrame& o) const {
  return id == o.id && extended == o.extended && rtr == o.rtr && error == o.error && len == o.len &&
         std::equal(data.begin(), data.begin() + std::min<int>(len, 8), o.data.begin());
}

std::string CanFrame::toString() const {
  char buf[64];
  int n = (extended || error) ? std::snprintf(buf, sizeof buf, "%08X#", id | (error ? 0x20000000u : 0u))
                              : std::snprintf(buf, sizeof buf, "%03X#", id);
  std::string s(buf, static_cast<std::size_t>(n));
  if (rtr) {
    s += 'R';
    if (len > 0) s += static_cast<char>('0' + len);
    return s;
  }
  for (int i = 0; i < len && i < 8; ++i) {
    std::snprintf(buf, sizeof buf, "%02X", data[static_cast<std::size_t>(i)]);
    s += buf;
  }
  return s;
}

std::string describeErrorFrame(const CanFrame& f) {
  if (!f.error) return {};
  std::string s;
  auto add = [&](const char* what) {
    if (!s.empty()) s += ", ";
    s += what;
  };
  if (f.id & err::kTxTimeout) add("tx timeout");
  if (f.id & err::kLostArbitration) add("lost arbitration");
  if (f.id & err::kController) {
    std::uint8_t c = f.data[1];
    std::string d = "controller:";
    if (c & 0x01) d += " rx overflow";
    if (c & 0x02) d += " tx overflow";
    if (c & 0x04) d += " rx warning";
    if (c & 0x08) d += " tx warning";
    if (c & 0x10) d += " rx error passive";
    if (c & 0x20) d += " tx error passive";
    if (c & 0x40) d += " back to error active";
    if (c == 0) d += " unspecified";
    add(d.c_str());
  }
  if (f.id & err::kProtocol) {
    std::uint8_t p = f.data[2];
    std::string d = "protocol violation:";
    if (p & 0x01) d += " single bit";
    if (p & 0x02) d += " frame format";
    if (p & 0x04) d += " bit stuffing";
    if (p & 0x08) d += " dominant bit not sent";
    if (p & 0x10) d += " recessive bit not sent";
    if (p & 0x20) d += " bus overload";
    if (p & 0x40) d += " active error announcement";
    if (p & 0x80) d += " during transmission";
    if (p == 0) d += " unspecified";
    add(d.c_str());
  }
  if (f.id & err::kTransceiver) add("transceiver problem");
  if (f.id & err::kNoAck) add("no acknowledgement (no other node on the bus?)");
  if (f.id & err::kBusOff) add("bus-off");
  if (f.id & err::kBusError) add("bus error");
  if (f.id & err::kRestarted) add("controller restarted");
  if (s.empty()) s = "error frame of unknown class";
  return s;
}

}  // namespace fusedet::drivers::canopen
