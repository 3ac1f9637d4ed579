// SPDX-License-Identifier: Apache-2.0
#pragma once
// Exit codes of the device commands (`fusedet camera`, `fusedet usb`), so scripts (the
// real-kernel test tier, udev helpers) can tell a missing device from a refused format.

#include <system_error>

#include "fusedet/core/result.h"

namespace fusedet::tools {

enum DeviceExit : int {
  kExitOk = 0,
  kExitError = 1,       // anything else (I/O error, libusb failure, unwritable output)
  kExitUsage = 2,       // malformed argument (e.g. VID:PID)
  kExitNoDevice = 3,    // node or USB device missing, or vanished
  kExitNotCapture = 4,  // not a V4L2 device, or not a streaming video capture device
  kExitRefused = 5,     // camera: no acceptable format/size/buffers; usb: several devices match
  kExitTimeout = 6,     // no frame in time
  kExitAccess = 7,      // permission denied or device busy
};

inline int exitCodeFor(const Error& e) {
  const std::error_code c = e.code;
  if (c == std::errc::no_such_file_or_directory || c == std::errc::no_such_device ||
      c == std::errc::no_such_device_or_address)
    return kExitNoDevice;
  if (c == std::errc::inappropriate_io_control_operation || c == std::errc::operation_not_supported) return kExitNotCapture;
  if (c == std::errc::invalid_argument || c == std::errc::not_enough_memory) return kExitRefused;
  if (c == std::errc::timed_out) return kExitTimeout;
  if (c == std::errc::permission_denied || c == std::errc::operation_not_permitted ||
      c == std::errc::device_or_resource_busy)
    return kExitAccess;
  return kExitError;
}

inline constexpr const char* kDeviceExitHelp =
    "Exit status: 0 success; 1 other error; 2 malformed argument; 3 device missing or vanished;\n"
    "4 not a V4L2 (streaming capture) device; 5 format/size/buffers refused (camera) or several\n"
    "devices match (usb); 6 no frame in time; 7 permission denied or device busy. Errors are printed\n"
    "to stderr as 'fusedet <command>: error: ...' naming the device; with --json also as\n"
    "{\"error\": ..., \"exit\": N} on stdout.\n";

}  // namespace fusedet::tools
