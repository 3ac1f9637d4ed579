// SPDX-License-Identifier: Apache-2.0
#pragma once
// UsbSysfs: what the kernel's sysfs tells about a USB device without opening it: its string
// attributes (serial, manufacturer, product) and the /dev nodes its interfaces' drivers made
// (ttyUSB* from usb-serial, ttyACM* from cdc-acm, video* from uvcvideo). Both roots are
// injectable so tests run on a fake tree.
//
// A device is named as in /sys/bus/usb/devices: "<bus>-<port>[.<port>...]" ("1-2.3"), root hubs "usb<bus>".

#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace fusedet::drivers::usb {

class UsbSysfs {
 public:
  explicit UsbSysfs(std::filesystem::path sysRoot = "/sys", std::filesystem::path devRoot = "/dev")
      : sysRoot_(std::move(sysRoot)), devRoot_(std::move(devRoot)) {}

  static std::string deviceName(std::uint8_t bus, std::span<const std::uint8_t> ports);

  // First line of <sysRoot>/bus/usb/devices/<device>/<attribute>, trailing whitespace removed.
  std::optional<std::string> attribute(const std::string& device, const std::string& name) const;
  // <devRoot>/ttyUSB0, <devRoot>/video0, ...: the nodes of every interface of the device,
  // sorted (tty before video, then by number), no duplicates. Empty when there are none (yet).
  std::vector<std::string> nodes(const std::string& device) const;

  const std::filesystem::path& sysRoot() const { return sysRoot_; }

 private:
  std::filesystem::path sysRoot_, devRoot_;
};

// True for node names fusedet resolves: ttyUSB<N>, ttyACM<N>, video<N>.
bool isDeviceNodeName(const std::string& name);

}  // namespace fusedet::drivers::usb
