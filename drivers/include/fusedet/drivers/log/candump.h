// SPDX-License-Identifier: Apache-2.0
#pragma once
// CAN frames between sensor logs and drivers/canopen: conversions between the log's CanMessage
// and canopen::CanFrame (what the buses and their recording hooks carry), and the export of a
// log's CAN traffic as a can-utils `candump -l` log through canopen::CandumpWriter (log2asc and
// canplayer read it; the stamps are the log's CLOCK_MONOTONIC seconds).

#include <cstdint>
#include <filesystem>
#include <string>

#include "fusedet/drivers/canopen/can_frame.h"
#include "fusedet/drivers/log/channels.h"

namespace fusedet::drivers::logs {

CanMessage toCanMessage(const canopen::CanFrame& frame, std::string interface);
canopen::CanFrame toCanFrame(const CanMessage& message);  // CanMessage data is at most 8 bytes (decodeCan checks)

// Writes every CAN frame of `log` (topic /tilt/can) in stamp order; returns the number written.
// Throws mcap::McapError (unreadable log) or std::runtime_error (cannot write `out`).
std::uint64_t exportCandump(const std::filesystem::path& log, const std::filesystem::path& out);

}  // namespace fusedet::drivers::logs
