// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/usb/usb_devices.h"

#include <libusb.h>

#include <algorithm>
#include <array>
#include <tuple>

#include "usb_describe.h"

namespace fusedet::drivers::usb {

std::string libusbErrorText(int code) {
  return std::string(libusb_error_name(code)) + ": " + libusb_strerror(code);
}

Result<UsbDeviceInfo> selectOne(const std::vector<UsbDeviceInfo>& devices, const UsbMatch& match) {
  std::vector<const UsbDeviceInfo*> hits;
  for (const UsbDeviceInfo& d : devices)
    if (match.matches(d.vendor, d.product, d.serial) && match.atPort(d.name)) hits.push_back(&d);
  if (hits.empty()) return makeError(std::errc::no_such_device, "usb " + match.toString() + ": no such device connected");
  if (hits.size() > 1) {
    std::string which;
    for (const UsbDeviceInfo* d : hits)
      which += (which.empty() ? "" : ", ") + d->name + (d->serial ? " serial " + *d->serial : " (no serial)");
    return makeError(std::errc::invalid_argument, "usb " + match.toString() + ": " + std::to_string(hits.size()) +
                                                      " devices match (" + which + "); add the serial (VID:PID:SERIAL) or the port (VID:PID@PORT)");
  }
  return *hits.front();
}

Result<std::string> nodeOf(const UsbDeviceInfo& device, const std::string& prefix) {
  for (const std::string& n : device.nodes) {
    const std::string base = n.substr(n.find_last_of('/') + 1);
    if (base.rfind(prefix, 0) == 0) return n;
  }
  return makeError(std::errc::no_such_device_or_address,
                   "usb " + device.id() + " at " + device.name + ": no /dev/" + prefix + "* node (yet)");
}

Result<std::unique_ptr<UsbBus>> UsbBus::open(UsbSysfs sysfs) {
  libusb_context* ctx = nullptr;
  if (const int r = libusb_init(&ctx); r != 0)
    return makeError(std::errc::io_error, "usb: cannot initialise libusb (" + libusbErrorText(r) + ")");
  return std::unique_ptr<UsbBus>(new UsbBus(ctx, std::move(sysfs)));
}

UsbBus::~UsbBus() { libusb_exit(ctx_); }

Result<std::vector<UsbDeviceInfo>> UsbBus::list(const std::optional<UsbMatch>& match) {
  libusb_device** devices = nullptr;
  const ssize_t n = libusb_get_device_list(ctx_, &devices);
  if (n < 0) return makeError(std::errc::io_error, "usb: cannot list devices (" + libusbErrorText(static_cast<int>(n)) + ")");
  std::vector<UsbDeviceInfo> out;
  for (ssize_t i = 0; i < n; ++i) {
    auto info = describeDevice(devices[i], sysfs_);
    if (!info) continue;  // a descriptor that cannot be read: the device is going away
    if (match && !(match->matches(info->vendor, info->product, info->serial) && match->atPort(info->name))) continue;
    out.push_back(std::move(*info));
  }
  libusb_free_device_list(devices, 1);
  std::sort(out.begin(), out.end(), [](const UsbDeviceInfo& a, const UsbDeviceInfo& b) {
    return std::tie(a.bus, a.name, a.address) < std::tie(b.bus, b.name, b.address);
  });
  return out;
}

Result<std::string> UsbBus::resolveNode(const UsbMatch& match, const std::string& prefix) {
  auto all = list(match);
  if (!all) return all.error();
  auto one = selectOne(*all, match);
  if (!one) return one.error();
  return nodeOf(*one, prefix);
}

Result<UsbDeviceInfo> UsbBus::reset(const UsbMatch& match) {
  auto all = list(match);
  if (!all) return all.error();
  auto one = selectOne(*all, match);
  if (!one) return one;
  libusb_device** devices = nullptr;
  const ssize_t n = libusb_get_device_list(ctx_, &devices);
  if (n < 0) return makeError(std::errc::io_error, "usb: cannot list devices (" + libusbErrorText(static_cast<int>(n)) + ")");
  Result<UsbDeviceInfo> result = makeError(std::errc::no_such_device, "usb " + match.toString() + " at " + one->name + ": gone before the reset");
  for (ssize_t i = 0; i < n; ++i) {
    if (libusb_get_bus_number(devices[i]) != one->bus || libusb_get_device_address(devices[i]) != one->address) continue;
    libusb_device_handle* h = nullptr;
    if (const int r = libusb_open(devices[i], &h); r != 0) {
      result = makeError(r == LIBUSB_ERROR_ACCESS ? std::errc::permission_denied : std::errc::io_error,
                         "usb " + match.toString() + " at " + one->name + ": cannot open (" + libusbErrorText(r) + ")");
      break;
    }
    const int r = libusb_reset_device(h);
    libusb_close(h);
    // NOT_FOUND: the device re-enumerated as a new one, which is what a reset is for.
    if (r == 0 || r == LIBUSB_ERROR_NOT_FOUND)
      result = *one;
    else
      result = makeError(std::errc::io_error, "usb " + match.toString() + " at " + one->name + ": reset failed (" + libusbErrorText(r) + ")");
    break;
  }
  libusb_free_device_list(devices, 1);
  return result;
}

}  // namespace fusedet::drivers::usb
