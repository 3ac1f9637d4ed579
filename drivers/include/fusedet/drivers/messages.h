// SPDX-License-Identifier: Apache-2.0
#pragma once
// Sensor messages: what the drivers emit and what fusion and the logs consume. Plain data;
// every stamp is CLOCK_MONOTONIC, taken as close to the hardware as possible.

#include <cstdint>
#include <string_view>
#include <vector>

#include "fusedet/core/stamp.h"

namespace fusedet::drivers {

// One scan of a 2D laser scanner (SICK LMS 291: 181..401 beams, counter-clockwise from 0° = right).
struct LaserScan {
  Stamp stamp;                // time of the first beam
  std::uint64_t sequence = 0; // scan counter of the driver (gaps = lost scans)
  double startAngle = 0;      // [rad] angle of the first beam, 0 = right, pi/2 = ahead
  double angleStep = 0;       // [rad] between beams (positive = counter-clockwise)
  double beamDuration = 0;    // [s] between two beams (scan time / beams); 0 = all at `stamp`
  std::vector<float> ranges;      // [m]; 0 or NaN = no valid return
  std::vector<float> remissions;  // [0..1] normalised, or raw; empty when the device sends none
  std::uint8_t status = 0;        // device status byte of the telegram (LMS: bits 0-2 severity)

  std::size_t size() const { return ranges.size(); }
  double beamAngle(std::size_t i) const { return startAngle + angleStep * static_cast<double>(i); }
  Stamp beamStamp(std::size_t i) const {
    return stamp + static_cast<std::int64_t>(beamDuration * 1e9 * static_cast<double>(i));
  }
};

// One position reading of the tilt (nodding) axis, from the motor's feedback.
struct TiltSample {
  Stamp stamp;
  double angle = 0;     // [rad]
  double velocity = 0;  // [rad/s]
};

enum class PixelFormat : std::uint8_t { kBgr24, kGray8, kYuyv, kMjpeg };
std::string_view toString(PixelFormat format);

// One camera image as captured (raw bytes in the device's format).
struct CameraFrame {
  Stamp stamp;
  std::uint64_t sequence = 0;
  int width = 0;
  int height = 0;
  int stride = 0;  // bytes per row (0 for compressed formats)
  PixelFormat format = PixelFormat::kBgr24;
  std::vector<std::uint8_t> bytes;
};

}  // namespace fusedet::drivers
