// SPDX-License-Identifier: Apache-2.0
#pragma once
// The sensor rig a Config describes, as the settings of the drivers, the log replay and the
// fusion: one mapping from config keys to library settings, for live mode and for replaying a
// log with the config it carries (metadata "fusedet.config", docs/log-format.md).

#include <Eigen/Geometry>
#include <filesystem>
#include <string>

#include "fusedet/daemon/config.h"
#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/drivers/v4l2/frame_stream.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/sweep_assembler.h"

namespace fusedet::daemon {

drivers::lms291::Lms291Config laserConfig(const Config& c);         // laser: device, baud, variant, remission, unit
drivers::logs::SensorReplayConfig sensorReplayConfig(const Config& c);  // laser + tilt (tiltDriveConfigFrom)
fusion::SweepConfig sweepConfig(const Config& c);                   // fusion: tilt axis offset, window; laser: remission scale
Eigen::Isometry3d laserToCamera(const Config& c);                   // fusion.laser_to_camera
drivers::v4l2::CameraConfig cameraConfig(const Config& c);          // camera: device, format, size, fps, buffers, controls
drivers::v4l2::FrameStreamTiming cameraTiming(const Config& c);     // camera: stall_ms, reconnect_max_s

// The rig a log replays with: `machine` with its laser, tilt, camera and fusion sections replaced
// by those of the log's metadata "fusedet.config", and the camera model (`camera.calibration:
// log:camera.yaml` = the log's own camera.yaml). A log without that metadata replays with the
// machine's sections (a relative calibration path is relative to `configDir`).
struct ReplayRig {
  Config config;
  fusion::CameraModel camera;
  std::string origin;  // where the rig came from, for the log
};
// Throws mcap::McapError (missing file, not MCAP), ConfigError (the log's config is bad),
// std::runtime_error (camera model).
ReplayRig replayRig(const std::filesystem::path& log, const Config& machine, const std::filesystem::path& configDir);

}  // namespace fusedet::daemon
