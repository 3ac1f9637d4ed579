#pragma once
// The sensor rig a Config describes, as the settings of the drivers, the log replay and the
// fusion: one mapping from config keys to library settings, for live mode and for replaying a
// log with the config it carries (metadata "fusedet.config", docs/log-format.md).

#include <Eigen/Geometry>

#include "fusedet/daemon/config.h"
#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/drivers/v4l2/frame_stream.h"
#include "fusedet/fusion/sweep_assembler.h"

namespace fusedet::daemon {

drivers::lms291::Lms291Config laserConfig(const Config& c);         // laser: device, baud, variant, remission, unit
drivers::logs::SensorReplayConfig sensorReplayConfig(const Config& c);  // laser + tilt (tiltDriveConfigFrom)
fusion::SweepConfig sweepConfig(const Config& c);                   // fusion: tilt axis offset, window; laser: remission scale
Eigen::Isometry3d laserToCamera(const Config& c);                   // fusion.laser_to_camera
drivers::v4l2::CameraConfig cameraConfig(const Config& c);          // camera: device, format, size, fps, buffers, controls
drivers::v4l2::FrameStreamTiming cameraTiming(const Config& c);     // camera: stall_ms, reconnect_max_s

}  // namespace fusedet::daemon
