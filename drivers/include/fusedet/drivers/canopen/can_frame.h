// SPDX-License-Identifier: Apache-2.0
#pragma once
// CanFrame: one classic CAN 2.0 frame (11- or 29-bit id, 0..8 data bytes, RTR, or a SocketCAN
// error frame) with its reception (or send) stamp.

#include <array>
#include <cstdint>
#include <initializer_list>
#include <string>

#include "fusedet/core/stamp.h"

namespace fusedet::drivers::canopen {

struct CanFrame {
  std::uint32_t id = 0;        // 11 bits (or 29 with `extended`); for error frames the error class bits
  bool extended = false;
  bool rtr = false;
  bool error = false;          // SocketCAN error frame (CAN_ERR_FLAG): `id` = class, data = details
  std::uint8_t len = 0;        // 0..8
  std::array<std::uint8_t, 8> data{};
  Stamp stamp;                 // reception (kernel) or send time, CLOCK_MONOTONIC
  bool kernelStamp = false;    // stamp came from the kernel (SocketCAN receive), not a clock read here

  static CanFrame make(std::uint32_t id, std::initializer_list<std::uint8_t> bytes);
  bool sameContent(const CanFrame& o) const;  // everything but the stamp
  std::string toString() const;               // candump style "123#DEADBEEF"
};

// Text for a SocketCAN error frame (class bits of the id and the detail bytes), e.g.
// "bus-off" or "controller: rx error passive". Empty for a non-error frame.
std::string describeErrorFrame(const CanFrame& f);

// Class bits of SocketCAN error frames (linux/can/error.h), repeated so callers need no kernel header.
namespace err {
inline constexpr std::uint32_t kTxTimeout = 0x001, kLostArbitration = 0x002, kController = 0x004,
                               kProtocol = 0x008, kTransceiver = 0x010, kNoAck = 0x020, kBusOff = 0x040,
                               kBusError = 0x080, kRestarted = 0x100;
}

}  // namespace fusedet::drivers::canopen
