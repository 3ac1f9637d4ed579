// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/protocol.h"

#include <cstdio>

namespace fusedet::drivers::lms291 {

namespace {
Error bad(const std::string& what) { return makeError(std::errc::bad_message, what); }
}  // namespace

std::optional<Mode> baudMode(int baud) {
  switch (baud) {
    case 9600: return Mode::kBaud9600;
    case 19200: return Mode::kBaud19200;
    case 38400: return Mode::kBaud38400;
    case 500000: return Mode::kBaud500000;
    default: return std::nullopt;
  }
}

std::optional<int> baudOfMode(std::uint8_t mode) {
  switch (static_cast<Mode>(mode)) {
    case Mode::kBaud9600: return 9600;
    case Mode::kBaud19200: return 19200;
    case Mode::kBaud38400: return 38400;
    case Mode::kBaud500000: return 500000;
    default: return std::nullopt;
  }
}

std::uint16_t baudWord(int baud) { return static_cast<std::uint16_t>(0x8000 | (1'000'000 / baud - 1)); }

std::optional<int> baudOfWord(std::uint16_t word) {
  for (int b : kBauds)
    if (baudWord(b) == word) return b;
  return std::nullopt;
}

std::string StatusByte::describe() const {
  static const char* const kSeverity[] = {"ok", "info", "warning", "error", "fatal", "severity 5",
                                          "severity 6", "severity 7"};
  std::string s = kSeverity[severity()];
  if (restart()) s += ", restart";
  if (implausible()) s += ", implausible values";
  if (pollution()) s += ", pollution";
  return s;
}

bool Variant::valid() const {
  if (angleDeg == 180) return resolutionCdeg == 100 || resolutionCdeg == 50;
  if (angleDeg == 100) return resolutionCdeg == 100 || resolutionCdeg == 50 || resolutionCdeg == 25;
  return false;
}

std::vector<std::uint8_t> variantPayload(Variant v) {
  std::vector<std::uint8_t> data;
  putU16(data, static_cast<std::uint16_t>(v.angleDeg));
  putU16(data, static_cast<std::uint16_t>(v.resolutionCdeg));
  return data;
}

int distanceBits(std::uint8_t measuringMode) {
  switch (measuringMode) {
    case 0x03: case 0x04: return 14;              // 16 m
    case 0x05: case 0x06: return 15;              // 32 m
    case 0x0F: case 0x3F: return 16;              // 32 m immediate / reflectivity
    default: return 13;                           // 8/80 m modes (and remission modes)
  }
}

std::uint16_t distanceMask(std::uint8_t measuringMode) {
  return static_cast<std::uint16_t>((1u << distanceBits(measuringMode)) - 1);
}

CountWord CountWord::decode(std::uint16_t w) {
  CountWord c;
  c.count = w & 0x3FF;
  c.partialIndex = (w >> 11) & 0x3;
  c.partial = (w >> 13) & 0x1;
  c.unit = ((w >> 14) & 0x3) == 1 ? Unit::kMm : Unit::kCm;
  return c;
}

std::uint16_t CountWord::encode() const {
  return static_cast<std::uint16_t>((count & 0x3FF) | ((partialIndex & 0x3) << 11) | (partial ? 1 << 13 : 0) |
                                    (unit == Unit::kMm ? 1 << 14 : 0));
}

Result<MeasuredValues> decodeMeasuredValues(std::span<const std::uint8_t> data) {
  if (data.size() < 2) return bad("measured values: " + std::to_string(data.size()) + " bytes, no count word");
  MeasuredValues v;
  v.countWord = CountWord::decode(u16(data, 0));
  const std::size_t n = static_cast<std::size_t>(v.countWord.count);
  const std::size_t plain = 2 + 2 * n;
  if (data.size() != plain && data.size() != plain + 2)
    return bad("measured values: count " + std::to_string(n) + " needs " + std::to_string(plain) +
               " bytes, telegram has " + std::to_string(data.size()));
  v.values.resize(n);
  for (std::size_t i = 0; i < n; ++i) v.values[i] = u16(data, 2 + 2 * i);
  if (data.size() == plain + 2) {
    v.scanIndex = data[plain];
    v.telegramIndex = data[plain + 1];
  }
  return v;
}

std::vector<std::uint8_t> encodeMeasuredValues(const MeasuredValues& v) {
  std::vector<std::uint8_t> out;
  out.reserve(4 + 2 * v.values.size());
  CountWord c = v.countWord;
  c.count = static_cast<int>(v.values.size());
  putU16(out, c.encode());
  for (std::uint16_t x : v.values) putU16(out, x);
  if (v.scanIndex && v.telegramIndex) {
    out.push_back(*v.scanIndex);
    out.push_back(*v.telegramIndex);
  }
  return out;
}

Result<std::vector<RemissionBlock>> decodeRangeRemission(std::span<const std::uint8_t> data) {
  if (data.size() < 2) return bad("range+remission: no block count");
  const std::size_t n = u16(data, 0);
  std::size_t at = 2;
  std::vector<RemissionBlock> blocks;
  for (std::size_t b = 0; b < n; ++b) {
    if (at + 6 > data.size()) return bad("range+remission: block " + std::to_string(b) + " header truncated");
    RemissionBlock r;
    r.start = u16(data, at);
    r.end = u16(data, at + 2);
    r.countWord = CountWord::decode(u16(data, at + 4));
    at += 6;
    const std::size_t cnt = static_cast<std::size_t>(r.countWord.count);
    if (at + 4 * cnt > data.size())
      return bad("range+remission: block " + std::to_string(b) + " needs " + std::to_string(4 * cnt) +
                 " value bytes, " + std::to_string(data.size() - at) + " left");
    for (std::size_t i = 0; i < cnt; ++i, at += 4) {
      r.ranges.push_back(u16(data, at));
      r.remissions.push_back(u16(data, at + 2));
    }
    blocks.push_back(std::move(r));
  }
  if (at != data.size())
    return bad("range+remission: " + std::to_string(data.size() - at) + " unexpected trailing bytes");
  return blocks;
}

std::vector<std::uint8_t> encodeRangeRemission(std::span<const RemissionBlock> blocks) {
  std::vector<std::uint8_t> out;
  putU16(out, static_cast<std::uint16_t>(blocks.size()));
  for (const RemissionBlock& r : blocks) {
    putU16(out, static_cast<std::uint16_t>(r.start));
    putU16(out, static_cast<std::uint16_t>(r.end));
    CountWord c = r.countWord;
    c.count = static_cast<int>(r.ranges.size());
    putU16(out, c.encode());
    for (std::size_t i = 0; i < r.ranges.size(); ++i) {
      putU16(out, r.ranges[i]);
      putU16(out, r.remissions[i]);
    }
  }
  return out;
}

// Offsets below count the B1 command byte as 0 (as the fact sheet does); data[i] = offset i + 1.
namespace status_offset {
constexpr std::size_t kFirmware = 1, kOperatingMode = 8, kDeviceStatus = 9, kVariant = 18,
                      kAngle = 107, kResolution = 109, kBaud = 116, kPermanentBaud = 119,
                      kAddress = 120, kUnit = 122, kLaserOn = 123;
}  // namespace status_offset

Result<DeviceStatus> decodeStatus(std::span<const std::uint8_t> data) {
  using namespace status_offset;
  if (data.size() < kLaserOn)
    return bad("status reply: " + std::to_string(data.size()) + " data bytes, need at least " +
               std::to_string(kLaserOn));
  auto at = [&](std::size_t offset) { return data[offset - 1]; };
  DeviceStatus s;
  for (std::size_t i = 0; i < 7; ++i) {
    const char c = static_cast<char>(at(kFirmware + i));
    if (c != 0) s.firmware.push_back(c);
  }
  s.operatingMode = at(kOperatingMode);
  s.deviceStatus = at(kDeviceStatus);
  s.variantType = at(kVariant);
  s.angleDeg = u16(data, kAngle - 1);
  s.resolutionCdeg = u16(data, kResolution - 1);
  s.baud = baudOfWord(u16(data, kBaud - 1));
  s.permanentBaud = at(kPermanentBaud) != 0;
  s.unit = at(kUnit) == 1 ? Unit::kMm : Unit::kCm;
  return s;
}

std::vector<std::uint8_t> encodeStatus(const DeviceStatus& s) {
  using namespace status_offset;
  std::vector<std::uint8_t> d(kStatusDataSize, 0);
  auto set = [&](std::size_t offset, std::uint8_t v) { d[offset - 1] = v; };
  auto set16 = [&](std::size_t offset, std::uint16_t v) {
    d[offset - 1] = static_cast<std::uint8_t>(v & 0xFF);
    d[offset] = static_cast<std::uint8_t>(v >> 8);
  };
  for (std::size_t i = 0; i < 7 && i < s.firmware.size(); ++i)
    set(kFirmware + i, static_cast<std::uint8_t>(s.firmware[i]));
  set(kOperatingMode, s.operatingMode);
  set(kDeviceStatus, s.deviceStatus);
  set(kVariant, s.variantType);
  set16(kAngle, static_cast<std::uint16_t>(s.angleDeg));
  set16(kResolution, static_cast<std::uint16_t>(s.resolutionCdeg));
  set16(kBaud, baudWord(s.baud.value_or(9600)));
  set(kPermanentBaud, s.permanentBaud ? 1 : 0);
  set(kAddress, 0);
  set(kUnit, s.unit == Unit::kMm ? 1 : 0);
  set(kLaserOn, 1);
  return d;
}

Result<ConfigBlock> decodeConfig(std::span<const std::uint8_t> data) {
  if (data.size() != kConfigSize && data.size() != 32)
    return bad("configuration: " + std::to_string(data.size()) + " bytes, expected 34 (or 32)");
  ConfigBlock c;
  c.bytes.assign(data.begin(), data.end());
  return c;
}

float valueToMeters(std::uint16_t value, std::uint8_t measuringMode, Unit unit) {
  const int bits = distanceBits(measuringMode);
  const std::uint32_t maxCode = (1u << bits) - 1;
  const std::uint32_t d = value & maxCode;
  if (d >= maxCode - 8) return 0.0f;  // 8183..8191 and analogues: no valid value
  return static_cast<float>(d * unitMeters(unit));
}

}  // namespace fusedet::drivers::lms291
