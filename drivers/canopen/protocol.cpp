// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/protocol.h"

#include <cstdio>

namespace fusedet::drivers::canopen {

CanFrame nmtFrame(NmtCommand cmd, int node) {
  return CanFrame::make(cob::kNmt, {static_cast<std::uint8_t>(cmd), static_cast<std::uint8_t>(node)});
}

std::string_view toString(NmtCommand c) {
  switch (c) {
    case NmtCommand::kStart: return "start";
    case NmtCommand::kStop: return "stop";
    case NmtCommand::kPreOperational: return "enter pre-operational";
    case NmtCommand::kResetNode: return "reset node";
    case NmtCommand::kResetCommunication: return "reset communication";
  }
  return "unknown NMT command";
}

std::string_view toString(NmtState s) {
  switch (s) {
    case NmtState::kBootUp: return "boot-up";
    case NmtState::kStopped: return "stopped";
    case NmtState::kOperational: return "operational";
    case NmtState::kPreOperational: return "pre-operational";
  }
  return "unknown";
}

std::optional<NmtState> parseNmtState(std::uint8_t b) {
  switch (b & 0x7F) {  // bit 7 is the toggle bit of node guarding
    case 0x00: return NmtState::kBootUp;
    case 0x04: return NmtState::kStopped;
    case 0x05: return NmtState::kOperational;
    case 0x7F: return NmtState::kPreOperational;
    default: return std::nullopt;
  }
}

CanFrame heartbeatFrame(int node, NmtState s) {
  return CanFrame::make(cob::kHeartbeat + static_cast<std::uint32_t>(node), {static_cast<std::uint8_t>(s)});
}

CanFrame syncFrame() { return CanFrame::make(cob::kSync, {}); }

namespace sdo {
std::uint8_t downloadCommand(int bytes) { return static_cast<std::uint8_t>(0x23 | ((4 - bytes) << 2)); }
std::uint8_t uploadExpeditedResponse(int bytes) { return static_cast<std::uint8_t>(0x43 | ((4 - bytes) << 2)); }
}  // namespace sdo

std::string abortCodeText(std::uint32_t code) {
  const char* text = "unknown abort code";
  switch (code) {
    case 0x05030000: text = "toggle bit not alternated"; break;
    case 0x05040000: text = "SDO protocol timed out"; break;
    case 0x05040001: text = "client/server command specifier not valid or unknown"; break;
    case 0x05040002: text = "invalid block size"; break;
    case 0x05040003: text = "invalid sequence number"; break;
    case 0x05040004: text = "CRC error"; break;
    case 0x05040005: text = "out of memory"; break;
    case 0x06010000: text = "unsupported access to an object"; break;
    case 0x06010001: text = "attempt to read a write only object"; break;
    case 0x06010002: text = "attempt to write a read only object"; break;
    case 0x06020000: text = "object does not exist in the object dictionary"; break;
    case 0x06040041: text = "object cannot be mapped to the PDO"; break;
    case 0x06040042: text = "the number and length of the objects to be mapped would exceed PDO length"; break;
    case 0x06040043: text = "general parameter incompatibility"; break;
    case 0x06040047: text = "general internal incompatibility in the device"; break;
    case 0x06060000: text = "access failed due to a hardware error"; break;
    case 0x06070010: text = "data type does not match, length of service parameter does not match"; break;
    case 0x06070012: text = "data type does not match, length of service parameter too high"; break;
    case 0x06070013: text = "data type does not match, length of service parameter too low"; break;
    case 0x06090011: text = "sub-index does not exist"; break;
    case 0x06090030: text = "invalid value for parameter"; break;
    case 0x06090031: text = "value of parameter written too high"; break;
    case 0x06090032: text = "value of parameter written too low"; break;
    case 0x06090036: text = "maximum value is less than minimum value"; break;
    case 0x060A0023: text = "resource not available: SDO connection"; break;
    case 0x08000000: text = "general error"; break;
    case 0x08000020: text = "data cannot be transferred or stored to the application"; break;
    case 0x08000021: text = "data cannot be transferred or stored to the application because of local control"; break;
    case 0x08000022: text = "data cannot be transferred or stored to the application because of the present device state"; break;
    case 0x08000023: text = "object dictionary dynamic generation fails or no object dictionary is present"; break;
    case 0x08000024: text = "no data available"; break;
    default: break;
  }
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08X ", code);
  return buf + std::string(text);
}

CanFrame sdoAbortFrame(std::uint32_t cobId, std::uint16_t index, std::uint8_t sub, std::uint32_t code) {
  CanFrame f = CanFrame::make(cobId, {sdo::kAbort, 0, 0, 0, 0, 0, 0, 0});
  writeLe(f.data, 1, index, 2);
  f.data[3] = sub;
  writeLe(f.data, 4, code, 4);
  return f;
}

std::optional<Emcy> parseEmcy(const CanFrame& f) {
  if (f.len < 3 || f.rtr || f.error) return std::nullopt;
  Emcy e;
  e.code = static_cast<std::uint16_t>(readLe(f.data, 0, 2));
  e.errorRegister = f.data[2];
  for (std::size_t i = 0; i < 5 && 3 + i < f.len; ++i) e.manufacturer[i] = f.data[3 + i];
  return e;
}

CanFrame emcyFrame(int node, const Emcy& e) {
  CanFrame f = CanFrame::make(cob::kEmcy + static_cast<std::uint32_t>(node), {0, 0, 0, 0, 0, 0, 0, 0});
  writeLe(f.data, 0, e.code, 2);
  f.data[2] = e.errorRegister;
  for (std::size_t i = 0; i < 5; ++i) f.data[3 + i] = e.manufacturer[i];
  return f;
}

std::string emcyCodeText(std::uint16_t code) {
  // Exact codes first (CiA 301 / CiA 402), then the class of the upper byte.
  const char* text = nullptr;
  switch (code) {
    case 0x0000: text = "error reset or no error"; break;
    case 0x2310: text = "continuous over-current"; break;
    case 0x3210: text = "DC link over-voltage"; break;
    case 0x3220: text = "DC link under-voltage"; break;
    case 0x4210: text = "excess temperature device"; break;
    case 0x5530: text = "data storage (EEPROM) error"; break;
    case 0x7300: text = "sensor (encoder) error"; break;
    case 0x8110: text = "CAN overrun (objects lost)"; break;
    case 0x8120: text = "CAN in error passive mode"; break;
    case 0x8130: text = "life guard or heartbeat error"; break;
    case 0x8140: text = "recovered from bus-off"; break;
    case 0x8611: text = "following error"; break;
    case 0xFF00: text = "device specific"; break;
    default: break;
  }
  if (!text) {
    switch (code >> 12) {
      case 0x1: text = "generic error"; break;
      case 0x2: text = "current"; break;
      case 0x3: text = "voltage"; break;
      case 0x4: text = "temperature"; break;
      case 0x5: text = "device hardware"; break;
      case 0x6: text = "device software"; break;
      case 0x7: text = "additional modules"; break;
      case 0x8: text = "monitoring / communication"; break;
      case 0x9: text = "external error"; break;
      case 0xF: text = "additional functions / device specific"; break;
      default: text = "unknown"; break;
    }
  }
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%04X ", code);
  return buf + std::string(text);
}

std::string errorRegisterText(std::uint8_t reg) {
  static constexpr const char* kBits[8] = {"generic", "current", "voltage", "temperature",
                                           "communication", "device profile", "reserved", "manufacturer"};
  std::string s;
  for (int i = 0; i < 8; ++i)
    if (reg & (1u << i)) s += (s.empty() ? "" : ", ") + std::string(kBits[i]);
  return s.empty() ? "none" : s;
}

std::string describe(const Emcy& e) {
  return "EMCY " + emcyCodeText(e.code) + " (error register: " + errorRegisterText(e.errorRegister) + ")";
}

DriveState decodeStatusword(std::uint16_t s) {
  switch (s & 0x4F) {
    case 0x00: return DriveState::kNotReadyToSwitchOn;
    case 0x40: return DriveState::kSwitchOnDisabled;
    case 0x08: return DriveState::kFault;
    case 0x0F: return DriveState::kFaultReactionActive;
    default: break;
  }
  switch (s & 0x6F) {
    case 0x21: return DriveState::kReadyToSwitchOn;
    case 0x23: return DriveState::kSwitchedOn;
    case 0x27: return DriveState::kOperationEnabled;
    case 0x07: return DriveState::kQuickStopActive;
    default: return DriveState::kUnknown;
  }
}

std::string_view toString(DriveState s) {
  switch (s) {
    case DriveState::kNotReadyToSwitchOn: return "not ready to switch on";
    case DriveState::kSwitchOnDisabled: return "switch on disabled";
    case DriveState::kReadyToSwitchOn: return "ready to switch on";
    case DriveState::kSwitchedOn: return "switched on";
    case DriveState::kOperationEnabled: return "operation enabled";
    case DriveState::kQuickStopActive: return "quick stop active";
    case DriveState::kFaultReactionActive: return "fault reaction active";
    case DriveState::kFault: return "fault";
    case DriveState::kUnknown: break;
  }
  return "unknown";
}

}  // namespace fusedet::drivers::canopen
