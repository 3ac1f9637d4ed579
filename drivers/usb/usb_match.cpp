// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/usb/usb_match.h"

#include <cstdio>

namespace fusedet::drivers::usb {
namespace {

std::optional<std::uint16_t> parseHex16(std::string_view s) {
  if (s.empty() || s.size() > 4) return std::nullopt;
  std::uint16_t v = 0;
  for (char c : s) {
    int d;
    if (c >= '0' && c <= '9') d = c - '0';
    else if (c >= 'a' && c <= 'f') d = c - 'a' + 10;
    else if (c >= 'A' && c <= 'F') d = c - 'A' + 10;
    else return std::nullopt;
    v = static_cast<std::uint16_t>(v * 16 + d);
  }
  return v;
}

// BUS-PORT[.PORT...], all decimal: "1-2", "3-1.4.2".
bool isPortName(std::string_view s) {
  const auto dash = s.find('-');
  if (dash == 0 || dash == std::string_view::npos || dash + 1 == s.size()) return false;
  char prev = '-';
  for (std::size_t i = 0; i < s.size(); ++i) {
    const char c = s[i];
    if (i == dash) continue;
    if (c == '.' && i > dash && prev != '.' && prev != '-' && i + 1 < s.size()) {
      prev = c;
      continue;
    }
    if (c < '0' || c > '9') return false;
    prev = c;
  }
  return true;
}

}  // namespace

std::string hex4(std::uint16_t v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "%04x", v);
  return buf;
}

bool UsbMatch::matches(std::uint16_t vid, std::uint16_t pid, const std::optional<std::string>& deviceSerial) const {
  if (vid != vendor || pid != product) return false;
  return !serial || (deviceSerial && *deviceSerial == *serial);
}

std::string UsbMatch::toString() const {
  return hex4(vendor) + ":" + hex4(product) + (serial ? ":" + *serial : "") + (port ? "@" + *port : "");
}

Result<UsbMatch> parseUsbMatch(std::string_view whole) {
  const auto bad = [&](const std::string& why) {
    return makeError(std::errc::invalid_argument,
                     "USB device '" + std::string(whole) + "': " + why + " (expected VID:PID[:SERIAL][@PORT], VID and PID in hex, e.g. 0403:6001 or 046d:0825@1-2.3)");
  };
  // "@PORT" at the end names the port; an '@' inside a serial stays part of it unless what follows
  // it is a port name.
  std::string_view text = whole;
  std::optional<std::string> port;
  if (const auto at = whole.rfind('@'); at != std::string_view::npos) {
    const std::string_view tail = whole.substr(at + 1);
    const bool hasSerial = whole.substr(0, at).find(':') != whole.substr(0, at).rfind(':');
    if (isPortName(tail)) {
      port = std::string(tail);
      text = whole.substr(0, at);
    } else if (!hasSerial) {
      return bad("port '" + std::string(tail) + "' is not BUS-PORT[.PORT...] as in /sys/bus/usb/devices (e.g. 1-2.3)");
    }
  }
  const auto c1 = text.find(':');
  if (c1 == std::string_view::npos) return bad("no ':' between vendor and product id");
  const auto c2 = text.find(':', c1 + 1);
  const std::string_view vid = text.substr(0, c1);
  const std::string_view pid = text.substr(c1 + 1, c2 == std::string_view::npos ? std::string_view::npos : c2 - c1 - 1);
  UsbMatch m;
  const auto v = parseHex16(vid);
  if (!v) return bad("vendor id '" + std::string(vid) + "' is not 1-4 hex digits");
  const auto p = parseHex16(pid);
  if (!p) return bad("product id '" + std::string(pid) + "' is not 1-4 hex digits");
  m.vendor = *v;
  m.product = *p;
  if (c2 != std::string_view::npos) {
    const std::string_view serial = text.substr(c2 + 1);
    if (serial.empty()) return bad("empty serial after the second ':'");
    for (char c : serial)
      if (static_cast<unsigned char>(c) < 0x21 || static_cast<unsigned char>(c) > 0x7E) return bad("the serial has a space or control character");
    m.serial = std::string(serial);
  }
  m.port = std::move(port);
  return m;
}

}  // namespace fusedet::drivers::usb
