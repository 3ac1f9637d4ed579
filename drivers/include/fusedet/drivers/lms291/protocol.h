// SPDX-License-Identifier: Apache-2.0
#pragma once
// SICK LMS 2xx protocol contents: commands, modes, baud codes, the status byte, and the decoding
// of measured-value (B0), range+remission (F5), status (B1) and configuration (F4) payloads.
// Facts: ../shared/docs/lms291-protocol.md (section numbers below refer to it).

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fusedet/core/result.h"

namespace fusedet::drivers::lms291 {

// Request commands (§3); the reply command is request + 0x80.
enum class Command : std::uint8_t {
  kReset = 0x10,
  kSwitchMode = 0x20,
  kRequestValues = 0x30,
  kStatus = 0x31,
  kErrors = 0x32,
  kType = 0x3A,
  kSetVariant = 0x3B,
  kReadConfig = 0x74,
  kWriteConfig = 0x77,
};
inline constexpr std::uint8_t kReplyBit = 0x80;
inline constexpr std::uint8_t kPowerOnReply = 0x90;
inline constexpr std::uint8_t kResetReply = 0x91;
inline constexpr std::uint8_t kUnknownCommandReply = 0x92;
inline constexpr std::uint8_t kMeasuredValues = 0xB0;
inline constexpr std::uint8_t kRangeRemission = 0xF5;

// Operating modes for 0x20 (§3).
enum class Mode : std::uint8_t {
  kInstallation = 0x00,
  kStreamAll = 0x24,
  kMonitoring = 0x25,  // values on request; power-on default; "stop streaming"
  kStreamPartial = 0x2A,
  kStreamRemission = 0x2B,
  kBaud38400 = 0x40,
  kBaud19200 = 0x41,
  kBaud9600 = 0x42,
  kBaud500000 = 0x48,
};
inline constexpr char kInstallPassword[] = "SICK_LMS";

inline constexpr std::array<int, 4> kBauds = {9600, 19200, 38400, 500000};
std::optional<Mode> baudMode(int baud);          // 38400 -> kBaud38400
std::optional<int> baudOfMode(std::uint8_t mode);
std::uint16_t baudWord(int baud);                // status word: 0x8000 | (1e6/baud - 1)
std::optional<int> baudOfWord(std::uint16_t word);
// Seconds one byte takes on the line at `baud` (8N1 = 10 bits).
inline double byteSeconds(int baud) { return 10.0 / baud; }

// Status byte (§4): severity in bits 0-2, flags above.
struct StatusByte {
  std::uint8_t raw = 0;
  int severity() const { return raw & 0x07; }  // 0 ok, 1 info, 2 warning, 3 error, 4 fatal
  bool restart() const { return raw & 0x20; }
  bool implausible() const { return raw & 0x40; }
  bool pollution() const { return raw & 0x80; }
  bool needsAttention() const { return severity() >= 2 || implausible() || pollution(); }
  std::string describe() const;  // "ok", "warning, pollution", ...
};

enum class Unit : std::uint8_t { kCm = 0, kMm = 1 };
inline double unitMeters(Unit u) { return u == Unit::kMm ? 1e-3 : 1e-2; }

// Scan variants (0x3B, §3): angle in degrees, resolution in 1/100 degree.
struct Variant {
  int angleDeg = 180;
  int resolutionCdeg = 50;
  bool valid() const;       // 180/100, 180/50, 100/100, 100/50, 100/25
  int beams() const { return angleDeg * 100 / resolutionCdeg + 1; }
  // Interlaced rotations per full scan: 1 at 1 deg, 2 at 0.5 deg, 4 at 0.25 deg.
  int rotations() const { return 100 / resolutionCdeg; }
  double startDeg() const { return (180 - angleDeg) / 2.0; }  // 100 deg variant covers 40..140
  auto operator<=>(const Variant&) const = default;
};

// 0x3B request data: angle u16, resolution u16 (e.g. B4 00 32 00 = 180 deg / 0.5 deg).
std::vector<std::uint8_t> variantPayload(Variant v);

// Measuring modes (config byte 5, §3) and the value bits they use (§4).
inline constexpr std::uint8_t kMeasuring8m = 0x00;    // 8/80 m, flags in bits 13-15
inline constexpr std::uint8_t kMeasuring32m = 0x06;   // 32 m + field A
inline constexpr std::uint8_t kMeasuringRemission = 0x0D;  // range + remission (F5 output)
int distanceBits(std::uint8_t measuringMode);  // 13, 14, 15 or 16
std::uint16_t distanceMask(std::uint8_t measuringMode);

// Count word of a measured-values block (§4).
struct CountWord {
  int count = 0;          // bits 0-9
  int partialIndex = 0;   // bits 11-12, start angle + 0.25 deg * index
  bool partial = false;   // bit 13
  Unit unit = Unit::kCm;  // bits 14-15
  static CountWord decode(std::uint16_t w);
  std::uint16_t encode() const;
};

// B0 payload: count word, values as sent, optional real-time indices.
struct MeasuredValues {
  CountWord countWord;
  std::vector<std::uint16_t> values;  // as sent (flag bits included)
  std::optional<std::uint8_t> scanIndex;      // real-time indices (config availability bit 02)
  std::optional<std::uint8_t> telegramIndex;
};
// `data` = telegram data after the command byte (without status). Errors name the problem.
Result<MeasuredValues> decodeMeasuredValues(std::span<const std::uint8_t> data);
std::vector<std::uint8_t> encodeMeasuredValues(const MeasuredValues& v);

// F5 payload: n subranges of (range, remission) pairs.
struct RemissionBlock {
  int start = 0, end = 0;  // 1-based inclusive beam numbers
  CountWord countWord;
  std::vector<std::uint16_t> ranges;
  std::vector<std::uint16_t> remissions;
};
Result<std::vector<RemissionBlock>> decodeRangeRemission(std::span<const std::uint8_t> data);
std::vector<std::uint8_t> encodeRangeRemission(std::span<const RemissionBlock> blocks);

// Status reply B1 (§3): the fields the driver checks. Offsets count the B1 byte as index 0.
inline constexpr std::size_t kStatusDataSize = 151;  // bytes after B1 (152 with the command)
struct DeviceStatus {
  std::string firmware;
  std::uint8_t operatingMode = 0;
  std::uint8_t deviceStatus = 0;
  std::uint8_t variantType = 0;
  int angleDeg = 0;
  int resolutionCdeg = 0;
  std::optional<int> baud;  // from the baud word
  bool permanentBaud = false;
  Unit unit = Unit::kCm;
};
Result<DeviceStatus> decodeStatus(std::span<const std::uint8_t> data);
std::vector<std::uint8_t> encodeStatus(const DeviceStatus& s);  // data after B1 (simulator)

// Configuration block (0x74 / 0x77, §3): 34 bytes (older firmware 32).
inline constexpr std::size_t kConfigSize = 34;
struct ConfigBlock {
  std::vector<std::uint8_t> bytes = std::vector<std::uint8_t>(kConfigSize, 0);
  std::uint8_t availability() const { return bytes[4]; }
  std::uint8_t measuringMode() const { return bytes[5]; }
  Unit unit() const { return bytes[6] == 1 ? Unit::kMm : Unit::kCm; }
  bool realTimeIndices() const { return bytes[4] & 0x02; }
};
Result<ConfigBlock> decodeConfig(std::span<const std::uint8_t> data);

// Values -> metres: special codes (no value, dazzle, overflow...) near the mode's maximum
// become 0 ("no valid return").
float valueToMeters(std::uint16_t value, std::uint8_t measuringMode, Unit unit);

inline std::uint16_t u16(std::span<const std::uint8_t> d, std::size_t at) {
  return static_cast<std::uint16_t>(d[at] | (d[at + 1] << 8));
}
inline void putU16(std::vector<std::uint8_t>& out, std::uint16_t v) {
  out.push_back(static_cast<std::uint8_t>(v & 0xFF));
  out.push_back(static_cast<std::uint8_t>(v >> 8));
}

}  // namespace fusedet::drivers::lms291
