// SPDX-License-Identifier: Apache-2.0
#pragma once
// The laser scans of a sensor log (docs/log-format.md), for `lms291-sim --log`: the log's raw
// serial channel read through logs::SensorReplay (the driver's telegram reader and scan
// decoder), kept in order together with the scan mode the log was recorded in. The simulator
// re-encodes them with its own encoder; it shares no encoder with the driver.

#include <filesystem>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::lms291::sim {

struct LoggedScans {
  Variant variant;          // angular range / resolution of every scan
  Unit unit = Unit::kMm;    // range unit the log's scanner was configured with
  bool remission = false;   // scans carry raw remission values
  std::vector<LaserScan> scans;  // in log order; ranges [m] (0 = no return), raw remissions
};

// Reads the scan mode from the log's rig (metadata "fusedet.config", section `laser`: angle_deg,
// resolution_deg, remission, range_unit; the fusedet.yaml defaults where absent) and decodes
// every scan. Errors: missing / unreadable log, no rig metadata, no scans, a scan whose size
// is not the mode's beam count.
Result<LoggedScans> loadLoggedScans(const std::filesystem::path& log);

}  // namespace fusedet::drivers::lms291::sim
