// SPDX-License-Identifier: Apache-2.0
#pragma once
// Format negotiation for V4L2 capture, as pure logic: what the device offers (filled from
// VIDIOC_ENUM_FMT / ENUM_FRAMESIZES / ENUM_FRAMEINTERVALS by V4l2Camera, or by a test) against
// what the configuration asks for. No ioctl here, so every rule is unit-tested without a device.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::v4l2 {

constexpr std::uint32_t makeFourcc(char a, char b, char c, char d) {
  return static_cast<std::uint32_t>(static_cast<unsigned char>(a)) |
         static_cast<std::uint32_t>(static_cast<unsigned char>(b)) << 8 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(c)) << 16 |
         static_cast<std::uint32_t>(static_cast<unsigned char>(d)) << 24;
}
constexpr std::uint32_t kFourccYuyv = makeFourcc('Y', 'U', 'Y', 'V');
constexpr std::uint32_t kFourccMjpeg = makeFourcc('M', 'J', 'P', 'G');
constexpr std::uint32_t kFourccJpeg = makeFourcc('J', 'P', 'E', 'G');  // some webcams: same stream

// "YUYV"; bytes outside printable ASCII as "0x%08X" of the whole code.
std::string fourccToString(std::uint32_t fourcc);
// The message format a fourcc is delivered as, if fusedet can decode it.
std::optional<PixelFormat> pixelFormatOf(std::uint32_t fourcc);

struct Fraction {
  std::uint32_t numerator = 0;
  std::uint32_t denominator = 0;
  bool valid() const { return numerator > 0 && denominator > 0; }
  double value() const { return valid() ? static_cast<double>(numerator) / denominator : 0.0; }
  bool operator==(const Fraction&) const = default;
};

// One frame-size entry: discrete (min == max, steps 0) or a stepwise/continuous range.
struct SizeRange {
  std::uint32_t minWidth = 0, maxWidth = 0, stepWidth = 0;
  std::uint32_t minHeight = 0, maxHeight = 0, stepHeight = 0;
  static SizeRange discrete(std::uint32_t w, std::uint32_t h) { return {w, w, 0, h, h, 0}; }
  bool isDiscrete() const { return minWidth == maxWidth && minHeight == maxHeight; }
  // A broken driver may report min > max or a zero size: such entries are never chosen.
  bool valid() const { return minWidth > 0 && minHeight > 0 && minWidth <= maxWidth && minHeight <= maxHeight; }
  bool contains(std::uint32_t w, std::uint32_t h) const;
  // The size in this range closest to w x h (clamped, then rounded to the step).
  std::pair<std::uint32_t, std::uint32_t> nearest(std::uint32_t w, std::uint32_t h) const;
  std::string toString() const;  // "640x480" or "16x16..4096x2160/+2+2"
};

// One frame-interval entry: discrete (min == max) or a stepwise/continuous range (seconds/frame).
struct IntervalRange {
  Fraction min, max, step;
  static IntervalRange discrete(Fraction f) { return {f, f, {}}; }
  bool isDiscrete() const { return min == max; }
  bool valid() const { return min.valid() && (isDiscrete() || (max.valid() && min.value() <= max.value())); }
};

struct FormatOffer {
  std::uint32_t fourcc = 0;
  std::string description;       // the driver's, e.g. "YUYV 4:2:2"
  std::vector<SizeRange> sizes;  // empty: the device does not enumerate its sizes
};

enum class FormatChoice { kYuyv, kMjpeg, kAuto };  // kAuto: YUYV if offered, else MJPEG
std::optional<FormatChoice> parseFormatChoice(std::string_view text);  // yuyv | mjpeg | auto
std::string_view toString(FormatChoice choice);

struct CaptureRequest {
  FormatChoice format = FormatChoice::kYuyv;
  std::uint32_t width = 640;
  std::uint32_t height = 480;
};

struct NegotiatedFormat {
  std::uint32_t fourcc = 0;
  PixelFormat pixelFormat = PixelFormat::kYuyv;
  std::uint32_t width = 0;
  std::uint32_t height = 0;
  bool sizeExact = true;  // false: the device does not offer the requested size; nearest taken
};

// Picks format and size. Error (invalid_argument) names the device, what was asked and everything
// the device offers, e.g. "camera /dev/video0: wants MJPEG; offers YUYV (640x480 1280x720), ...".
Result<NegotiatedFormat> negotiateFormat(const std::string& device, std::span<const FormatOffer> offers,
                                         const CaptureRequest& request);
// "YUYV UYVY (640x480 1280x720), RGB3 (16x16..1920x1080/+2+2)": formats with the same sizes
// together, in the order offered; "none" when empty.
std::string describeOffers(std::span<const FormatOffer> offers);

// The offered frame interval closest to 1/fps (ranges: clamped and rounded to their step).
// Empty when nothing is offered (the device does not enumerate intervals).
std::optional<Fraction> chooseInterval(std::span<const IntervalRange> offers, double fps);

}  // namespace fusedet::drivers::v4l2
