// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/frame_text.h"

#include <cstdio>

#include "fusedet/drivers/canopen/protocol.h"

namespace fusedet::drivers::canopen {

namespace {
std::string bytes(const CanFrame& f, std::size_t from = 0) {
  std::string s;
  char buf[4];
  for (std::size_t i = from; i < f.len; ++i) {
    std::snprintf(buf, sizeof buf, "%s%02X", s.empty() ? "" : " ", f.data[i]);
    s += buf;
  }
  return s;
}
std::string object(const CanFrame& f) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X:%02X", static_cast<unsigned>(readLe(f.data, 1, 2)), f.data[3]);
  return buf;
}

std::string sdoText(const CanFrame& f, bool request) {
  if (f.len < 8) return "short SDO frame";
  const std::uint8_t c = f.data[0];
  const int cs = c >> 5;
  if (cs == 4) return "abort " + object(f) + ": " + abortCodeText(readLe(f.data, 4, 4));
  if (request) {
    switch (cs) {
      case 1: {
        if (!(c & 0x02)) return "segmented download " + object(f);
        const int n = (c & 0x01) ? 4 - ((c >> 2) & 3) : 4;
        char buf[32];
        std::snprintf(buf, sizeof buf, " = 0x%0*X", n * 2, readLe(f.data, 4, n));
        return "download " + object(f) + buf;
      }
      case 2: return "upload " + object(f);
      case 3: return std::string("upload segment, toggle ") + ((c & 0x10) ? "1" : "0");
      default: return "command 0x" + bytes(f).substr(0, 2);
    }
  }
  switch (cs) {
    case 3: return "download " + object(f) + " ok";
    case 2: {
      if (!(c & 0x02)) return "upload " + object(f) + " segmented, " + std::to_string(readLe(f.data, 4, 4)) + " bytes";
      const int n = (c & 0x01) ? 4 - ((c >> 2) & 3) : 4;
      char buf[32];
      std::snprintf(buf, sizeof buf, " = 0x%0*X", n * 2, readLe(f.data, 4, n));
      return "upload " + object(f) + buf;
    }
    case 0: {
      const int n = 7 - ((c >> 1) & 7);
      std::string text(f.data.begin() + 1, f.data.begin() + 1 + n);
      for (char& ch : text)
        if (ch < 32 || ch > 126) ch = '.';
      return std::string("segment, toggle ") + ((c & 0x10) ? "1" : "0") + ((c & 1) ? ", last" : "") + ": \"" + text + "\"";
    }
    default: return "command 0x" + bytes(f).substr(0, 2);
  }
}
}  // namespace

std::string describeFrame(const CanFrame& f) {
  if (f.error) return "error frame: " + describeErrorFrame(f);
  if (f.extended) return "extended frame (not CANopen): " + f.toString();
  if (f.rtr) return "remote request " + f.toString();
  const CobId c = splitCobId(f.id);
  const std::string node = " node " + std::to_string(c.node);
  if (f.id == cob::kNmt) {
    if (f.len < 2) return "NMT (short)";
    return "NMT " + std::string(toString(static_cast<NmtCommand>(f.data[0]))) +
           (f.data[1] == 0 ? " all nodes" : " node " + std::to_string(f.data[1]));
  }
  if (f.id == cob::kSync) return "SYNC";
  switch (c.function) {
    case cob::kEmcy: {
      auto e = parseEmcy(f);
      return "EMCY" + node + ": " + (e ? describe(*e) : "short frame " + bytes(f));
    }
    case 0x180: case 0x280: case 0x380: case 0x480:
      return "TPDO" + std::to_string((c.function - 0x080) / 0x100) + node + ": " + bytes(f);
    case 0x200: case 0x300: case 0x400: case 0x500:
      return "RPDO" + std::to_string((c.function - 0x100) / 0x100) + node + ": " + bytes(f);
    case cob::kSdoTx: return "SDO response" + node + ": " + sdoText(f, false);
    case cob::kSdoRx: return "SDO request" + node + ": " + sdoText(f, true);
    case cob::kHeartbeat: {
      if (f.len < 1) return "heartbeat" + node + " (empty)";
      auto s = parseNmtState(f.data[0]);
      return "heartbeat" + node + ": " + (s ? std::string(toString(*s)) : "unknown state " + bytes(f));
    }
    default: return "frame " + f.toString();
  }
}

}  // namespace fusedet::drivers::canopen
