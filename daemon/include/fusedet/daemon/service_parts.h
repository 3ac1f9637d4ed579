// SPDX-License-Identifier: Apache-2.0
#pragma once
// The parts of a Service a config asks for: live devices (laser, tilt, camera) or, when
// `replay.file` is set, a sensor log replayed through the same pipeline with the log's own rig
// (laser, tilt, camera, fusion) and this config's detection, models and socket. The listener is
// left to the caller (socket activation or bind).

#include <filesystem>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/service.h"

namespace fusedet::daemon {

// Models, calibration and a relative replay.file resolve against configFile's folder. Throws
// std::runtime_error naming the file that is missing or bad (a log that is not MCAP, a camera
// model, a model file).
ServiceParts liveParts(Config config, const std::filesystem::path& configFile);
// withModels false: no detector (the caller brings one), so no model file is read.
ServiceParts replayParts(Config config, const std::filesystem::path& configFile, bool withModels = true);
// replayParts when replay.file is set, else liveParts.
ServiceParts serviceParts(Config config, const std::filesystem::path& configFile);

}  // namespace fusedet::daemon
