#pragma once
// UsbMatch: which USB device is meant, written VID:PID[:SERIAL] in hex (e.g. "0403:6001" or
// "0403:6001:A50285BI"), as in the configuration and `fusedet usb reset`.

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

  // `serial`: the device's serial string, if it could be read (a serial match needs one).
  bool matches(std::uint16_t vid, std::uint16_t pid, const std::optional<std::string>& deviceSerial) const;
  std::string toString() const;  // "0403:6001" or "0403:6001:A50285BI"
};

// Errors (invalid_argument) quote the text and say what is expected.
Result<UsbMatch> parseUsbMatch(std::string_view text);

std::string hex4(std::uint16_t v);  // "0403"

}  // namespace fusedet::drivers::usb
