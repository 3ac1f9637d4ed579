// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/controls.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>

namespace fusedet::drivers::v4l2 {
namespace {

const ControlInfo* find(const std::map<std::uint32_t, ControlInfo>& present, std::uint32_t id) {
  const auto it = present.find(id);
  return it == present.end() || !it->second.writable ? nullptr : &it->second;
}

bool hasMenuItem(const ControlInfo& c, std::int32_t item) {
  return std::find(c.menuItems.begin(), c.menuItems.end(), item) != c.menuItems.end();
}

// Clamps to the range and rounds to the step; notes when the value had to change.
std::int32_t fit(const ControlInfo& c, std::int64_t wanted, const std::string& name, std::vector<std::string>& notes) {
  std::int64_t v = std::clamp<std::int64_t>(wanted, c.minimum, c.maximum);
  if (c.step > 1) v = c.minimum + (v - c.minimum + c.step / 2) / c.step * c.step;
  v = std::min<std::int64_t>(v, c.maximum);
  if (v != wanted)
    notes.push_back(name + " " + std::to_string(wanted) + " is not available; using " + std::to_string(v) + " (range " +
                    std::to_string(c.minimum) + ".." + std::to_string(c.maximum) + ", step " + std::to_string(c.step) + ")");
  return static_cast<std::int32_t>(v);
}

void planExposure(const ControlSetting& s, const std::map<std::uint32_t, ControlInfo>& present, ControlPlan& plan) {
  const ControlInfo* mode = find(present, V4L2_CID_EXPOSURE_AUTO);
  if (s.automatic) {
    if (!mode) {
      plan.notes.push_back("exposure: the device has no exposure mode control; it keeps its own setting");
      return;
    }
    // UVC cameras usually offer only manual and aperture priority (auto exposure, fixed iris).
    for (std::int32_t m : {V4L2_EXPOSURE_AUTO, V4L2_EXPOSURE_APERTURE_PRIORITY})
      if (mode->menuItems.empty() || hasMenuItem(*mode, m)) {
        plan.writes.push_back({V4L2_CID_EXPOSURE_AUTO, m, "exposure_auto"});
        return;
      }
    plan.notes.push_back("exposure: the device offers no automatic exposure mode; it keeps its own setting");
    return;
  }
  const ControlInfo* absolute = find(present, V4L2_CID_EXPOSURE_ABSOLUTE);
  if (!absolute) {
    plan.notes.push_back("exposure: the device has no absolute exposure control; fixed exposure " +
                         std::to_string(s.value) + " us not applied");
    return;
  }
  if (mode) {
    if (!mode->menuItems.empty() && !hasMenuItem(*mode, V4L2_EXPOSURE_MANUAL)) {
      plan.notes.push_back("exposure: the device offers no manual exposure mode; fixed exposure not applied");
      return;
    }
    plan.writes.push_back({V4L2_CID_EXPOSURE_AUTO, V4L2_EXPOSURE_MANUAL, "exposure_auto"});
  }
  // V4L2_CID_EXPOSURE_ABSOLUTE counts in 100 us units.
  const auto units = static_cast<std::int64_t>(std::llround(s.value / 100.0));
  plan.writes.push_back({V4L2_CID_EXPOSURE_ABSOLUTE, fit(*absolute, units, "exposure [100 us]", plan.notes), "exposure_absolute"});
}

void planGain(const ControlSetting& s, const std::map<std::uint32_t, ControlInfo>& present, ControlPlan& plan) {
  const ControlInfo* autogain = find(present, V4L2_CID_AUTOGAIN);
  if (s.automatic) {
    if (!autogain) {
      plan.notes.push_back("gain: the device has no automatic gain control; it keeps its own setting");
      return;
    }
    plan.writes.push_back({V4L2_CID_AUTOGAIN, 1, "autogain"});
    return;
  }
  const ControlInfo* gain = find(present, V4L2_CID_GAIN);
  if (!gain) {
    plan.notes.push_back("gain: the device has no gain control; fixed gain " + std::to_string(s.value) + " not applied");
    return;
  }
  if (autogain) plan.writes.push_back({V4L2_CID_AUTOGAIN, 0, "autogain"});
  plan.writes.push_back({V4L2_CID_GAIN, fit(*gain, s.value, "gain", plan.notes), "gain"});
}

}  // namespace

std::optional<ControlSetting> parseControlSetting(std::string_view text) {
  if (text == "auto") return ControlSetting{};
  if (text.empty() || text.size() > 10) return std::nullopt;
  std::int64_t v = 0;
  for (char c : text) {
    if (c < '0' || c > '9') return std::nullopt;
    v = v * 10 + (c - '0');
  }
  if (v > INT32_MAX) return std::nullopt;
  return ControlSetting{false, static_cast<std::int32_t>(v)};
}

std::vector<std::uint32_t> controlIdsOfInterest() {
  return {V4L2_CID_EXPOSURE_AUTO, V4L2_CID_EXPOSURE_ABSOLUTE, V4L2_CID_AUTOGAIN, V4L2_CID_GAIN};
}

ControlPlan planControls(const ControlsConfig& config, const std::map<std::uint32_t, ControlInfo>& present) {
  ControlPlan plan;
  planExposure(config.exposure, present, plan);
  planGain(config.gain, present, plan);
  return plan;
}

}  // namespace fusedet::drivers::v4l2
