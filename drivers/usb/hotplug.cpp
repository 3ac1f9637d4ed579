// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/usb/hotplug.h"

#include <libusb.h>

#include "usb_describe.h"

namespace fusedet::drivers::usb {

struct HotplugTrampoline {
  static int LIBUSB_CALL call(libusb_context*, libusb_device* device, libusb_hotplug_event event, void* self) {
    static_cast<UsbHotplug*>(self)->handle(device, static_cast<int>(event));
    return 0;  // stay registered
  }
};

Result<std::unique_ptr<UsbHotplug>> UsbHotplug::start(std::optional<UsbMatch> match, Callback callback, UsbSysfs sysfs) {
  std::unique_ptr<UsbHotplug> h(new UsbHotplug(std::move(match), std::move(callback), std::move(sysfs)));
  if (const int r = libusb_init(&h->ctx_); r != 0) {
    h->ctx_ = nullptr;
    return makeError(std::errc::io_error, "usb: cannot initialise libusb (" + libusbErrorText(r) + ")");
  }
  if (!libusb_has_capability(LIBUSB_CAP_HAS_HOTPLUG))
    return makeError(std::errc::operation_not_supported, "usb: this libusb has no hotplug support");
  const int vid = h->match_ ? h->match_->vendor : LIBUSB_HOTPLUG_MATCH_ANY;
  const int pid = h->match_ ? h->match_->product : LIBUSB_HOTPLUG_MATCH_ANY;
  const int r = libusb_hotplug_register_callback(
      h->ctx_, static_cast<libusb_hotplug_event>(LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED | LIBUSB_HOTPLUG_EVENT_DEVICE_LEFT),
      LIBUSB_HOTPLUG_ENUMERATE, vid, pid, LIBUSB_HOTPLUG_MATCH_ANY, &HotplugTrampoline::call, h.get(), &h->handle_);
  if (r != LIBUSB_SUCCESS)
    return makeError(std::errc::io_error, "usb: cannot register a hotplug callback (" + libusbErrorText(r) + ")");
  h->running_ = true;
  UsbHotplug* self = h.get();
  h->thread_ = std::thread([self] {
    while (self->running_) {
      timeval tv{0, 100'000};  // stop() is noticed within 100 ms
      libusb_handle_events_timeout_completed(self->ctx_, &tv, nullptr);
    }
  });
  return h;
}

void UsbHotplug::handle(void* device, int event) {
  auto* dev = static_cast<libusb_device*>(device);
  const std::pair<int, int> key{libusb_get_bus_number(dev), libusb_get_device_address(dev)};
  if (event == LIBUSB_HOTPLUG_EVENT_DEVICE_ARRIVED) {
    auto info = describeDevice(dev, sysfs_, /*mayOpen=*/false);
    if (!info) return;
    if (match_ && !(match_->matches(info->vendor, info->product, info->serial) && match_->atPort(info->name))) return;
    present_[key] = *info;
    callback_(HotplugEvent::kArrived, *info);
    return;
  }
  const auto it = present_.find(key);
  if (it == present_.end()) return;  // not one of ours
  const UsbDeviceInfo info = it->second;
  present_.erase(it);
  callback_(HotplugEvent::kLeft, info);
}

void UsbHotplug::stop() {
  if (running_.exchange(false) && thread_.joinable()) thread_.join();
  if (ctx_) {
    libusb_hotplug_deregister_callback(ctx_, handle_);
    libusb_exit(ctx_);
    ctx_ = nullptr;
  }
}

UsbHotplug::~UsbHotplug() { stop(); }

}  // namespace fusedet::drivers::usb
