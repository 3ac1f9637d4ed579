// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/negotiation.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>

namespace fusedet::drivers::v4l2 {
namespace {

std::uint32_t clampStep(std::uint32_t v, std::uint32_t lo, std::uint32_t hi, std::uint32_t step) {
  v = std::clamp(v, lo, hi);
  if (step == 0) return v;
  const std::uint32_t k = (v - lo + step / 2) / step;
  return std::min(lo + k * step, hi - (hi - lo) % step);
}

std::uint64_t sizeDistance(std::uint32_t w, std::uint32_t h, std::uint32_t W, std::uint32_t H) {
  const auto d = [](std::uint32_t a, std::uint32_t b) { return a > b ? a - b : b - a; };
  return static_cast<std::uint64_t>(d(w, W)) + d(h, H);
}

// The format codes to look for, most preferred first.
std::vector<std::uint32_t> candidates(FormatChoice choice) {
  switch (choice) {
    case FormatChoice::kYuyv: return {kFourccYuyv};
    case FormatChoice::kMjpeg: return {kFourccMjpeg, kFourccJpeg};
    case FormatChoice::kAuto: return {kFourccYuyv, kFourccMjpeg, kFourccJpeg};
  }
  return {};
}

}  // namespace

std::string fourccToString(std::uint32_t fourcc) {
  constexpr std::uint32_t kBigEndian = 1u << 31;  // V4L2_PIX_FMT_FLAG_BE on a 4-letter code
  if ((fourcc & kBigEndian) && (fourcc & ~kBigEndian) >> 24 >= 0x20) {
    const std::string base = fourccToString(fourcc & ~kBigEndian);
    if (base.rfind("0x", 0) != 0) return base + "-BE";
  }
  std::string s;
  for (int i = 0; i < 4; ++i) {
    const char c = static_cast<char>((fourcc >> (8 * i)) & 0xFF);
    if (c < 0x20 || c > 0x7E) {
      char hex[16];
      std::snprintf(hex, sizeof hex, "0x%08X", fourcc);
      return hex;
    }
    s += c;
  }
  // Codes shorter than four letters are padded with spaces (e.g. "Y8  "); keep them readable.
  while (!s.empty() && s.back() == ' ') s.pop_back();
  return s;
}

std::optional<PixelFormat> pixelFormatOf(std::uint32_t fourcc) {
  if (fourcc == kFourccYuyv) return PixelFormat::kYuyv;
  if (fourcc == kFourccMjpeg || fourcc == kFourccJpeg) return PixelFormat::kMjpeg;
  return std::nullopt;
}

bool SizeRange::contains(std::uint32_t w, std::uint32_t h) const {
  if (!valid()) return false;
  if (w < minWidth || w > maxWidth || h < minHeight || h > maxHeight) return false;
  if (stepWidth != 0 && (w - minWidth) % stepWidth != 0) return false;
  if (stepHeight != 0 && (h - minHeight) % stepHeight != 0) return false;
  return true;
}

std::pair<std::uint32_t, std::uint32_t> SizeRange::nearest(std::uint32_t w, std::uint32_t h) const {
  if (!valid()) return {minWidth, minHeight};
  return {clampStep(w, minWidth, maxWidth, stepWidth), clampStep(h, minHeight, maxHeight, stepHeight)};
}

std::string SizeRange::toString() const {
  std::string s = std::to_string(minWidth) + "x" + std::to_string(minHeight);
  if (isDiscrete()) return s;
  s += ".." + std::to_string(maxWidth) + "x" + std::to_string(maxHeight);
  if (stepWidth > 1 || stepHeight > 1) s += "/+" + std::to_string(stepWidth) + "+" + std::to_string(stepHeight);
  return s;
}

std::optional<FormatChoice> parseFormatChoice(std::string_view text) {
  if (text == "yuyv") return FormatChoice::kYuyv;
  if (text == "mjpeg") return FormatChoice::kMjpeg;
  if (text == "auto") return FormatChoice::kAuto;
  return std::nullopt;
}

std::string_view toString(FormatChoice choice) {
  switch (choice) {
    case FormatChoice::kYuyv: return "YUYV";
    case FormatChoice::kMjpeg: return "MJPEG";
    case FormatChoice::kAuto: return "YUYV or MJPEG";
  }
  return "?";
}

std::string describeOffers(std::span<const FormatOffer> offers) {
  if (offers.empty()) return "none";
  // Formats with the same sizes are listed together (vivid offers ~40 formats, all alike).
  std::vector<std::pair<std::string, std::string>> groups;  // fourccs, sizes
  for (const FormatOffer& f : offers) {
    std::string sizes;
    for (const SizeRange& r : f.sizes) {
      if (!sizes.empty()) sizes += ' ';
      sizes += r.toString();
    }
    if (sizes.empty()) sizes = "sizes not enumerated";
    const auto same = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.second == sizes; });
    if (same != groups.end()) {
      same->first += ' ';
      same->first += fourccToString(f.fourcc);
    } else {
      groups.emplace_back(fourccToString(f.fourcc), sizes);
    }
  }
  std::string s;
  for (const auto& [codes, sizes] : groups) {
    if (!s.empty()) s += ", ";
    s += codes;
    s += " (";
    s += sizes;
    s += ')';
  }
  return s;
}

Result<NegotiatedFormat> negotiateFormat(const std::string& device, std::span<const FormatOffer> offers,
                                         const CaptureRequest& request) {
  const FormatOffer* chosen = nullptr;
  for (std::uint32_t code : candidates(request.format)) {
    const auto it = std::find_if(offers.begin(), offers.end(), [code](const FormatOffer& f) { return f.fourcc == code; });
    if (it != offers.end()) {
      chosen = &*it;
      break;
    }
  }
  if (chosen == nullptr)
    return makeError(std::errc::invalid_argument, "camera " + device + ": wants " + std::string(toString(request.format)) +
                                                      "; the device offers " + describeOffers(offers));
  NegotiatedFormat n;
  n.fourcc = chosen->fourcc;
  n.pixelFormat = *pixelFormatOf(chosen->fourcc);
  n.width = request.width;
  n.height = request.height;
  const bool anyValid = std::any_of(chosen->sizes.begin(), chosen->sizes.end(), [](const SizeRange& r) { return r.valid(); });
  if (!anyValid) return n;  // nothing (usable) enumerated: S_FMT tells what the device makes of it
  for (const SizeRange& r : chosen->sizes)
    if (r.contains(request.width, request.height)) return n;
  std::uint64_t best = UINT64_MAX;
  for (const SizeRange& r : chosen->sizes) {
    if (!r.valid()) continue;
    const auto [w, h] = r.nearest(request.width, request.height);
    const std::uint64_t d = sizeDistance(w, h, request.width, request.height);
    // Ties go to the larger image: downscaling later loses less than upscaling.
    if (d < best || (d == best && static_cast<std::uint64_t>(w) * h > static_cast<std::uint64_t>(n.width) * n.height)) {
      best = d;
      n.width = w;
      n.height = h;
    }
  }
  n.sizeExact = false;
  return n;
}

std::optional<Fraction> chooseInterval(std::span<const IntervalRange> offers, double fps) {
  std::optional<Fraction> best;
  double bestDistance = 0;
  const double target = fps > 0 ? 1.0 / fps : 0.0;
  for (const IntervalRange& r : offers) {
    if (!r.valid()) continue;
    Fraction f = r.min;
    if (!r.isDiscrete()) {
      const double t = std::clamp(target, r.min.value(), r.max.value());
      if (r.step.valid()) {
        // min + k * step as one exact fraction, reduced.
        const auto k = static_cast<std::uint64_t>(std::llround((t - r.min.value()) / r.step.value()));
        std::uint64_t num = std::uint64_t{r.min.numerator} * r.step.denominator + k * r.step.numerator * r.min.denominator;
        std::uint64_t den = std::uint64_t{r.min.denominator} * r.step.denominator;
        const std::uint64_t g = std::gcd(num, den);
        num /= g, den /= g;
        if (num <= UINT32_MAX && den <= UINT32_MAX && static_cast<double>(num) / static_cast<double>(den) <= r.max.value() + 1e-12)
          f = Fraction{static_cast<std::uint32_t>(num), static_cast<std::uint32_t>(den)};
        else
          f = r.max;
      } else {
        f = Fraction{1000, static_cast<std::uint32_t>(std::clamp(std::round(1000.0 / t), 1.0, 4e9))};
        // Rounding to 1000/n may step just outside the range: its ends are exact then.
        if (f.value() < r.min.value()) f = r.min;
        if (f.value() > r.max.value()) f = r.max;
      }
    }
    if (!f.valid()) continue;
    const double distance = std::abs(1.0 / f.value() - fps);
    // Ties go to the higher rate (shorter interval).
    if (!best || distance < bestDistance - 1e-9 || (std::abs(distance - bestDistance) <= 1e-9 && f.value() < best->value())) {
      best = f;
      bestDistance = distance;
    }
  }
  return best;
}

}  // namespace fusedet::drivers::v4l2
