// SPDX-License-Identifier: Apache-2.0
#pragma once
// USB devices through libusb: list those matching VID:PID[:SERIAL] with their /dev nodes (via
// UsbSysfs), and reset one that stopped answering (USBDEVFS_RESET through libusb_reset_device;
// the kernel re-enumerates it, so its nodes come back, possibly under new names).

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/usb/sysfs.h"
#include "fusedet/drivers/usb/usb_match.h"

struct libusb_context;

namespace fusedet::drivers::usb {

struct UsbDeviceInfo {
  std::uint16_t vendor = 0, product = 0;
  std::uint8_t bus = 0, address = 0;
  std::string name;  // sysfs name, e.g. "1-2.3" ("usb1" for a root hub)
  std::optional<std::string> serial, manufacturer, productName;
  std::vector<std::string> nodes;  // /dev/ttyUSB0, /dev/video0, ...
  std::string id() const { return hex4(vendor) + ":" + hex4(product); }
};

// Exactly one device of `devices` must match: errors no_such_device (none) or invalid_argument
// (several: they are listed and the serial is suggested).
Result<UsbDeviceInfo> selectOne(const std::vector<UsbDeviceInfo>& devices, const UsbMatch& match);
// The first node of `device` whose name starts with `prefix` ("video", "ttyUSB", "tty");
// no_such_device_or_address when the device has none (its driver not bound yet, or another kind).
Result<std::string> nodeOf(const UsbDeviceInfo& device, const std::string& prefix);

// The devices sysfs shows under <sysRoot>/bus/usb/devices (root hubs excluded), those matching
// `match` (ids, serial, port), in port order. Needs no libusb or usbfs, only a readable /sys: what
// a sandboxed service can always do. bus/address come from busnum/devnum.
std::vector<UsbDeviceInfo> listFromSysfs(const UsbSysfs& sysfs, const std::optional<UsbMatch>& match = std::nullopt);
// The node (name starting with `prefix`) of the one device matching `match`, from sysfs alone:
// errors as selectOne (none: no_such_device; several: invalid_argument) and nodeOf (no node yet).
Result<std::string> resolveNodeFromSysfs(const UsbSysfs& sysfs, const UsbMatch& match, const std::string& prefix);

class UsbBus {
 public:
  // libusb_init. Errors (io_error) carry libusb's words, e.g. when the machine has no usbfs.
  static Result<std::unique_ptr<UsbBus>> open(UsbSysfs sysfs = UsbSysfs());
  ~UsbBus();
  UsbBus(const UsbBus&) = delete;
  UsbBus& operator=(const UsbBus&) = delete;

  // All devices (no match) or those matching, in bus/port order.
  Result<std::vector<UsbDeviceInfo>> list(const std::optional<UsbMatch>& match = std::nullopt);
  // The node (name starting with `prefix`: "video", "ttyUSB", "tty") of the one device matching
  // `match`: what the daemon opens when the configuration names a USB camera or adapter by id.
  Result<std::string> resolveNode(const UsbMatch& match, const std::string& prefix);
  // Resets the one matching device; returns it as it was found before the reset.
  Result<UsbDeviceInfo> reset(const UsbMatch& match);

  const UsbSysfs& sysfs() const { return sysfs_; }

 private:
  UsbBus(libusb_context* ctx, UsbSysfs sysfs) : ctx_(ctx), sysfs_(std::move(sysfs)) {}
  libusb_context* ctx_;
  UsbSysfs sysfs_;
};

// "LIBUSB_ERROR_ACCESS: Access denied (insufficient permissions)"
std::string libusbErrorText(int code);

}  // namespace fusedet::drivers::usb
