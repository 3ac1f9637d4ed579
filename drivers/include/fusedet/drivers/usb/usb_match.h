// SPDX-License-Identifier: Apache-2.0
#pragma once
// UsbMatch: which USB device is meant, written VID:PID[:SERIAL][@PORT] in hex (e.g. "0403:6001",
// "0403:6001:A50285BI" or "046d:0825@1-2.3"), as in the configuration and `fusedet usb reset`.
// PORT is the device's place on the bus as sysfs names it (BUS-PORT[.PORT...]): it tells apart
// identical devices without serial numbers, and stays the same when the device is re-plugged
// into the same socket.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "fusedet/core/result.h"

namespace fusedet::drivers::usb {

struct UsbMatch {
  std::uint16_t vendor = 0;
  std::uint16_t product = 0;
  std::optional<std::string> serial;  // empty: any serial
  std::optional<std::string> port;    // empty: any port; else a sysfs device name such as "1-2.3"

  // `serial`: the device's serial string, if it could be read (a serial match needs one).
  bool matches(std::uint16_t vid, std::uint16_t pid, const std::optional<std::string>& deviceSerial) const;
  // True when no port is asked for or `deviceName` (sysfs name, "1-2.3") is that port.
  bool atPort(const std::string& deviceName) const { return !port || *port == deviceName; }
  std::string toString() const;  // "0403:6001", "0403:6001:A50285BI", "046d:0825@1-2.3"
};

// Errors (invalid_argument) quote the text and say what is expected.
Result<UsbMatch> parseUsbMatch(std::string_view text);

std::string hex4(std::uint16_t v);  // "0403"

}  // namespace fusedet::drivers::usb
