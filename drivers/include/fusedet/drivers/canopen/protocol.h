// SPDX-License-Identifier: Apache-2.0
#pragma once
// CANopen CiA 301 / CiA 402 facts (design.md §3): COB-IDs, NMT, SDO command bytes, abort codes,
// EMCY, heartbeat states, statusword/controlword. Pure functions, no I/O.

#include <algorithm>
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

#include "fusedet/drivers/canopen/can_frame.h"

namespace fusedet::drivers::canopen {

// COB-IDs (predefined connection set).
namespace cob {
inline constexpr std::uint32_t kNmt = 0x000, kSync = 0x080, kEmcy = 0x080, kTpdo1 = 0x180, kRpdo1 = 0x200,
                               kSdoTx = 0x580 /* server -> client */, kSdoRx = 0x600 /* client -> server */,
                               kHeartbeat = 0x700;
inline constexpr std::uint32_t tpdo(int n, int node) { return 0x080u + 0x100u * static_cast<std::uint32_t>(n) + static_cast<std::uint32_t>(node); }
inline constexpr std::uint32_t rpdo(int n, int node) { return 0x100u + 0x100u * static_cast<std::uint32_t>(n) + static_cast<std::uint32_t>(node); }
}  // namespace cob

// Function code and node of a predefined-set COB-ID (node 0 for NMT and SYNC).
struct CobId {
  std::uint32_t function = 0;  // id & 0x780
  int node = 0;                // id & 0x7F
};
inline CobId splitCobId(std::uint32_t id) { return {id & 0x780u, static_cast<int>(id & 0x7Fu)}; }

enum class NmtCommand : std::uint8_t {
  kStart = 0x01, kStop = 0x02, kPreOperational = 0x80, kResetNode = 0x81, kResetCommunication = 0x82
};
CanFrame nmtFrame(NmtCommand cmd, int node);  // node 0 = all nodes
std::string_view toString(NmtCommand c);

enum class NmtState : std::uint8_t { kBootUp = 0x00, kStopped = 0x04, kOperational = 0x05, kPreOperational = 0x7F };
std::string_view toString(NmtState s);
CanFrame heartbeatFrame(int node, NmtState s);
std::optional<NmtState> parseNmtState(std::uint8_t b);

CanFrame syncFrame();

// SDO command specifiers (first byte).
namespace sdo {
inline constexpr std::uint8_t kDownloadExpedited4 = 0x23, kDownloadExpedited3 = 0x27, kDownloadExpedited2 = 0x2B,
                              kDownloadExpedited1 = 0x2F, kDownloadResponse = 0x60, kUploadRequest = 0x40,
                              kUploadSegmentedStart = 0x41, kUploadSegmentRequest = 0x60, kAbort = 0x80;
// Expedited download command for 1..4 bytes; expedited upload response is the same with 0x40.
std::uint8_t downloadCommand(int bytes);
std::uint8_t uploadExpeditedResponse(int bytes);
}  // namespace sdo

// Common abort codes (CiA 301 table 22).
namespace abortcode {
inline constexpr std::uint32_t kToggleBit = 0x05030000, kTimeout = 0x05040000, kBadCommand = 0x05040001,
                               kUnsupportedAccess = 0x06010000, kReadOnly = 0x06010002, kWriteOnly = 0x06010001,
                               kNoObject = 0x06020000, kNotMappable = 0x06040041, kLengthMismatch = 0x06070010,
                               kNoSubindex = 0x06090011, kValueRange = 0x06090030, kGeneral = 0x08000000,
                               kDeviceState = 0x08000022;
}
std::string abortCodeText(std::uint32_t code);  // "0x06020000 object does not exist in the object dictionary"

CanFrame sdoAbortFrame(std::uint32_t cob, std::uint16_t index, std::uint8_t sub, std::uint32_t code);

// EMCY: error code (u16), error register (u8), 5 manufacturer bytes. Code 0 = error reset.
struct Emcy {
  std::uint16_t code = 0;
  std::uint8_t errorRegister = 0;
  std::array<std::uint8_t, 5> manufacturer{};
};
std::optional<Emcy> parseEmcy(const CanFrame& f);  // nullopt if fewer than 3 data bytes
CanFrame emcyFrame(int node, const Emcy& e);
std::string emcyCodeText(std::uint16_t code);        // "0x8611 following error"
std::string errorRegisterText(std::uint8_t reg);     // "generic, current"
std::string describe(const Emcy& e);

// CiA 402 power state machine, as read from the statusword.
enum class DriveState : std::uint8_t {
  kNotReadyToSwitchOn, kSwitchOnDisabled, kReadyToSwitchOn, kSwitchedOn, kOperationEnabled,
  kQuickStopActive, kFaultReactionActive, kFault, kUnknown
};
DriveState decodeStatusword(std::uint16_t sw);
std::string_view toString(DriveState s);
namespace sw {
inline constexpr std::uint16_t kWarning = 1u << 7, kTargetReached = 1u << 10, kSetPointAck = 1u << 12,
                               kFollowingError = 1u << 13;
}
namespace cw {
inline constexpr std::uint16_t kShutdown = 0x06, kSwitchOn = 0x07, kEnableOperation = 0x0F, kDisableVoltage = 0x00,
                               kQuickStop = 0x02, kFaultReset = 0x80, kNewSetPoint = 1u << 4,
                               kChangeImmediately = 1u << 5, kHalt = 1u << 8;
}

// Object indices used by the tilt drive and the simulator.
namespace od {
inline constexpr std::uint16_t kDeviceType = 0x1000, kErrorRegister = 0x1001, kDeviceName = 0x1008,
                               kHeartbeatProducer = 0x1017, kTpdo1Comm = 0x1800, kTpdo1Map = 0x1A00,
                               kErrorCode = 0x603F, kControlword = 0x6040, kStatusword = 0x6041,
                               kModeOfOperation = 0x6060, kModeDisplay = 0x6061, kPositionActual = 0x6064,
                               kFollowingErrorWindow = 0x6065, kVelocityActual = 0x606C, kTargetPosition = 0x607A,
                               kMaxProfileVelocity = 0x607F, kProfileVelocity = 0x6081,
                               kProfileAcceleration = 0x6083, kProfileDeceleration = 0x6084;
inline constexpr std::int8_t kProfilePositionMode = 1;
}  // namespace od

// Little-endian helpers for SDO and PDO payloads.
inline std::uint32_t readLe(std::span<const std::uint8_t> b, std::size_t at, int bytes) {
  std::uint32_t v = 0;
  for (int i = bytes - 1; i >= 0; --i) v = v << 8 | b[at + static_cast<std::size_t>(i)];
  return v;
}
// Writes at most 4 bytes and never past the span: callers pass 1..4 bytes that fit, which GCC 12
// for aarch64 cannot prove at -O3 (-Wstringop-overflow in the SDO client).
inline void writeLe(std::span<std::uint8_t> b, std::size_t at, std::uint32_t v, int bytes) {
  const std::size_t room = at < b.size() ? b.size() - at : 0;
  const std::size_t n = std::min(static_cast<std::size_t>(std::clamp(bytes, 0, 4)), room);
  for (std::size_t i = 0; i < n; ++i) b[at + i] = static_cast<std::uint8_t>(v >> (8 * i));
}

}  // namespace fusedet::drivers::canopen
