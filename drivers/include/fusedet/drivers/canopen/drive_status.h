// SPDX-License-Identifier: Apache-2.0
#pragma once
// queryDriveStatus: a one-shot look at a CiA 402 drive over SDO (what `fusedet tilt status`
// prints): device type and name, NMT state (from its heartbeat or boot-up, if heard), statusword
// and state, mode, position, error code, heartbeat producer time. Changes nothing on the drive.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "fusedet/core/result.h"
#include "fusedet/drivers/canopen/can_bus.h"
#include "fusedet/drivers/canopen/protocol.h"

namespace fusedet::drivers::canopen {

struct DriveStatusReport {
  std::uint32_t deviceType = 0;
  std::string deviceName;
  std::optional<NmtState> nmt;      // heard within the query
  std::uint16_t statusword = 0;
  DriveState state = DriveState::kUnknown;
  std::int8_t mode = 0;             // 0x6061
  std::int32_t position = 0;        // 0x6064 [counts]
  std::uint16_t errorCode = 0;      // 0x603F
  std::uint16_t heartbeatMs = 0;    // 0x1017
};

// Errors: the first SDO failure (timeout = no such node, or an abort with its text).
Result<DriveStatusReport> queryDriveStatus(CanBus& bus, int node,
                                           std::chrono::milliseconds sdoTimeout = std::chrono::milliseconds(500));

}  // namespace fusedet::drivers::canopen
