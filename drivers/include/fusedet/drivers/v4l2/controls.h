// SPDX-License-Identifier: Apache-2.0
#pragma once
// Exposure and gain: automatic or fixed from the configuration. planControls() turns the
// configuration and what the device reported for its controls (VIDIOC_QUERYCTRL/QUERYMENU)
// into the VIDIOC_S_CTRL writes to make, in order, plus notes for what could not be done as
// asked (control missing, value clamped). Pure logic; V4l2Camera does the ioctls.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::drivers::v4l2 {

struct ControlSetting {
  bool automatic = true;
  std::int32_t value = 0;  // used when !automatic: exposure in microseconds, gain in device units
};

// "auto" or a non-negative decimal integer (as in the configuration and on the command line).
std::optional<ControlSetting> parseControlSetting(std::string_view text);

struct ControlsConfig {
  ControlSetting exposure;
  ControlSetting gain;
};

// What VIDIOC_QUERYCTRL (and QUERYMENU for menus) said about one control.
struct ControlInfo {
  std::int32_t minimum = 0, maximum = 0, step = 1, defaultValue = 0;
  bool writable = true;                // not disabled, not read-only, not inactive-only
  std::vector<std::int32_t> menuItems;  // valid indices of a menu control
};

struct ControlWrite {
  std::uint32_t id = 0;
  std::int32_t value = 0;
  std::string name;  // e.g. "exposure_auto" (for logs and errors)
};

struct ControlPlan {
  std::vector<ControlWrite> writes;
  std::vector<std::string> notes;  // each a complete sentence about one control
};

// The control ids planControls() looks at (V4L2_CID_EXPOSURE_AUTO, _EXPOSURE_ABSOLUTE, _AUTOGAIN, _GAIN).
std::vector<std::uint32_t> controlIdsOfInterest();

// `present`: the controls the device has, by id (absent = no such control).
ControlPlan planControls(const ControlsConfig& config, const std::map<std::uint32_t, ControlInfo>& present);

}  // namespace fusedet::drivers::v4l2
