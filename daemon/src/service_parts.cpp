// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/service_parts.h"

#include <spdlog/spdlog.h>

#include "fusedet/daemon/camera_source.h"
#include "fusedet/daemon/lms291_source.h"
#include "fusedet/daemon/replay_source.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/daemon/tilt_source.h"

namespace fusedet::daemon {

ServiceParts liveParts(Config config, const std::filesystem::path& configFile) {
  ServiceParts parts;
  parts.fuser = fuserFrom(config, configFile);
  parts.detector = detectorFrom(config, configFile, *parts.fuser);
  parts.sources.push_back(std::make_unique<Lms291Source>(config));
  parts.sources.push_back(std::make_unique<TiltSource>(config.tilt));
  parts.sources.push_back(std::make_unique<CameraSource>(config.camera));
  parts.configFile = configFile;
  parts.config = std::move(config);
  parts.mode = "live";
  return parts;
}

// The log's rig (laser, tilt, camera, fusion) with this machine's detection, models and
// socket; a missing or non-MCAP log is a start-up error naming the file.
ServiceParts replayParts(Config config, const std::filesystem::path& configFile, bool withModels) {
  std::filesystem::path log = config.replay.file;
  if (log.is_relative()) log = configFile.parent_path() / log;
  ReplayRig rig;
  try {
    rig = replayRig(log, config, configFile.parent_path());
  } catch (const std::exception& e) {
    throw std::runtime_error("replay.file " + log.string() + ": " + e.what());
  }
  spdlog::info("replaying {} ({}, at end: {}) with the rig from {}", log.string(),
               config.replay.realtime ? fmt::format("recorded speed x{:g}", config.replay.speed) : "as fast as possible",
               config.replay.atEnd, rig.origin);
  ReplaySettings settings;
  settings.log = log;
  settings.sensors = sensorReplayConfig(rig.config);
  settings.realtime = config.replay.realtime;
  settings.speed = config.replay.speed;
  settings.restamp = config.replay.restamp;
  settings.loop = config.replay.atEnd == "loop";
  ServiceParts parts;
  parts.fuser = fuserFrom(rig.config, rig.camera, neuralLayersFrom(config, configFile));
  if (withModels) parts.detector = detectorFrom(config, configFile, *parts.fuser);
  try {
    parts.sources.push_back(std::make_unique<ReplaySource>(settings));
  } catch (const std::exception& e) {
    throw std::runtime_error("replay.file " + log.string() + ": " + e.what());
  }
  parts.sensorConfig = std::move(rig.config);
  parts.lossless = !config.replay.realtime;
  parts.wallClockStamps = config.replay.realtime && config.replay.speed == 1.0 && config.replay.restamp;
  parts.configFile = configFile;
  parts.config = std::move(config);
  parts.mode = "replay";
  return parts;
}

ServiceParts serviceParts(Config config, const std::filesystem::path& configFile) {
  return config.replay.file.empty() ? liveParts(std::move(config), configFile) : replayParts(std::move(config), configFile);
}

}  // namespace fusedet::daemon
