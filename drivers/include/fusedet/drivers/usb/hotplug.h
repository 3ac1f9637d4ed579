// SPDX-License-Identifier: Apache-2.0
#pragma once
// UsbHotplug: libusb hotplug callbacks on their own thread, so the daemon reopens a replugged
// laser adapter or camera at once instead of waiting for its back-off. Where libusb has no
// hotplug support (start() says operation_not_supported) the drivers still find a returning
// device by watching its node.
//
// An arrival is reported when the kernel has enumerated the device; its interface drivers (and so
// its /dev nodes) may bind a moment later: `nodes` may be empty then. A departure reports the
// device as it was seen arriving (its strings are gone with it).

#include <atomic>
#include <functional>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <thread>

#include "fusedet/core/result.h"
#include "fusedet/drivers/usb/usb_devices.h"

struct libusb_context;

namespace fusedet::drivers::usb {

enum class HotplugEvent { kArrived, kLeft };

class UsbHotplug {
 public:
  using Callback = std::function<void(HotplugEvent, const UsbDeviceInfo&)>;

  // Watches devices matching `match` (all when empty). Devices already present are reported as
  // arrivals first. The callback runs on the hotplug thread.
  static Result<std::unique_ptr<UsbHotplug>> start(std::optional<UsbMatch> match, Callback callback,
                                                   UsbSysfs sysfs = UsbSysfs());
  ~UsbHotplug();
  UsbHotplug(const UsbHotplug&) = delete;
  UsbHotplug& operator=(const UsbHotplug&) = delete;
  void stop();

 private:
  UsbHotplug(std::optional<UsbMatch> match, Callback callback, UsbSysfs sysfs)
      : match_(std::move(match)), callback_(std::move(callback)), sysfs_(std::move(sysfs)) {}
  void handle(void* device, int event);  // from the libusb callback
  friend struct HotplugTrampoline;

  std::optional<UsbMatch> match_;
  Callback callback_;
  UsbSysfs sysfs_;
  libusb_context* ctx_ = nullptr;
  int handle_ = 0;
  std::atomic<bool> running_{false};
  std::thread thread_;
  std::map<std::pair<int, int>, UsbDeviceInfo> present_;  // by (bus, address); hotplug thread only
};

}  // namespace fusedet::drivers::usb
