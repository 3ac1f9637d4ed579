// SPDX-License-Identifier: Apache-2.0
#pragma once
// Internal: one libusb_device as a UsbDeviceInfo (listing and hotplug share it).

#include <libusb.h>

#include "fusedet/drivers/usb/usb_devices.h"

namespace fusedet::drivers::usb {

// Descriptor ids, bus position, sysfs name and nodes; strings from sysfs (no open needed), or
// from the device's string descriptors when sysfs has none and `mayOpen` (never inside a
// hotplug callback, where libusb forbids device I/O).
Result<UsbDeviceInfo> describeDevice(libusb_device* device, const UsbSysfs& sysfs, bool mayOpen = true);

}  // namespace fusedet::drivers::usb
