// SPDX-License-Identifier: Apache-2.0
// listFromSysfs / resolveNodeFromSysfs: USB devices as sysfs describes them, without libusb.

#include <algorithm>
#include <charconv>
#include <tuple>

#include "fusedet/drivers/usb/usb_devices.h"

namespace fusedet::drivers::usb {
namespace {

std::optional<unsigned> number(const std::optional<std::string>& text, int base) {
  if (!text || text->empty()) return std::nullopt;
  unsigned v = 0;
  const auto [end, ec] = std::from_chars(text->data(), text->data() + text->size(), v, base);
  if (ec != std::errc() || end != text->data() + text->size()) return std::nullopt;
  return v;
}

}  // namespace

std::vector<UsbDeviceInfo> listFromSysfs(const UsbSysfs& sysfs, const std::optional<UsbMatch>& match) {
  std::vector<UsbDeviceInfo> out;
  std::error_code ec;
  for (std::filesystem::directory_iterator it(sysfs.sysRoot() / "bus/usb/devices", ec), end; !ec && it != end;
       it.increment(ec)) {
    const std::string name = it->path().filename().string();
    // Interfaces are "<device>:<config>.<interface>"; root hubs "usb<bus>".
    if (name.find(':') != std::string::npos || name.rfind("usb", 0) == 0) continue;
    const auto vendor = number(sysfs.attribute(name, "idVendor"), 16);
    const auto product = number(sysfs.attribute(name, "idProduct"), 16);
    if (!vendor || !product || *vendor > 0xffff || *product > 0xffff) continue;  // unplugged while read
    UsbDeviceInfo info;
    info.vendor = static_cast<std::uint16_t>(*vendor);
    info.product = static_cast<std::uint16_t>(*product);
    info.bus = static_cast<std::uint8_t>(number(sysfs.attribute(name, "busnum"), 10).value_or(0));
    info.address = static_cast<std::uint8_t>(number(sysfs.attribute(name, "devnum"), 10).value_or(0));
    info.name = name;
    info.serial = sysfs.attribute(name, "serial");
    if (match && !(match->matches(info.vendor, info.product, info.serial) && match->atPort(name))) continue;
    info.manufacturer = sysfs.attribute(name, "manufacturer");
    info.productName = sysfs.attribute(name, "product");
    info.nodes = sysfs.nodes(name);
    out.push_back(std::move(info));
  }
  std::sort(out.begin(), out.end(), [](const UsbDeviceInfo& a, const UsbDeviceInfo& b) {
    return std::tie(a.bus, a.name, a.address) < std::tie(b.bus, b.name, b.address);
  });
  return out;
}

Result<std::string> resolveNodeFromSysfs(const UsbSysfs& sysfs, const UsbMatch& match, const std::string& prefix) {
  auto one = selectOne(listFromSysfs(sysfs, match), match);
  if (!one) return one.error();
  return nodeOf(*one, prefix);
}

}  // namespace fusedet::drivers::usb
