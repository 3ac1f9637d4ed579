// SPDX-License-Identifier: Apache-2.0
#include "usb_describe.h"

#include <array>

namespace fusedet::drivers::usb {
namespace {

std::optional<std::string> stringDescriptor(libusb_device_handle* h, std::uint8_t index) {
  if (h == nullptr || index == 0) return std::nullopt;
  std::array<unsigned char, 256> buf{};
  const int n = libusb_get_string_descriptor_ascii(h, index, buf.data(), static_cast<int>(buf.size()));
  if (n <= 0) return std::nullopt;
  return std::string(reinterpret_cast<const char*>(buf.data()), static_cast<std::size_t>(n));
}

}  // namespace

Result<UsbDeviceInfo> describeDevice(libusb_device* device, const UsbSysfs& sysfs, bool mayOpen) {
  libusb_device_descriptor d{};
  if (const int r = libusb_get_device_descriptor(device, &d); r != 0)
    return makeError(std::errc::io_error, "usb: device descriptor (" + libusbErrorText(r) + ")");
  UsbDeviceInfo info;
  info.vendor = d.idVendor;
  info.product = d.idProduct;
  info.bus = libusb_get_bus_number(device);
  info.address = libusb_get_device_address(device);
  std::array<std::uint8_t, 8> ports{};
  const int n = libusb_get_port_numbers(device, ports.data(), static_cast<int>(ports.size()));
  info.name = UsbSysfs::deviceName(info.bus, std::span<const std::uint8_t>(ports.data(), n > 0 ? static_cast<std::size_t>(n) : 0));
  info.serial = sysfs.attribute(info.name, "serial");
  info.manufacturer = sysfs.attribute(info.name, "manufacturer");
  info.productName = sysfs.attribute(info.name, "product");
  info.nodes = sysfs.nodes(info.name);
  const bool missing = (d.iSerialNumber && !info.serial) || (d.iManufacturer && !info.manufacturer) || (d.iProduct && !info.productName);
  if (missing && mayOpen) {
    // No sysfs (or another layout): ask the device itself, if we may open it.
    libusb_device_handle* h = nullptr;
    if (libusb_open(device, &h) == 0) {
      if (!info.serial) info.serial = stringDescriptor(h, d.iSerialNumber);
      if (!info.manufacturer) info.manufacturer = stringDescriptor(h, d.iManufacturer);
      if (!info.productName) info.productName = stringDescriptor(h, d.iProduct);
      libusb_close(h);
    }
  }
  return info;
}

}  // namespace fusedet::drivers::usb
