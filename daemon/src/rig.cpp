// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/rig.h"

#include <cmath>

#include "fusedet/daemon/tilt_source.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::daemon {

drivers::lms291::Lms291Config laserConfig(const Config& c) {
  drivers::lms291::Lms291Config l;
  l.device = c.laser.device;
  l.baud = c.laser.baud;
  l.variant = drivers::lms291::Variant{c.laser.angleDeg, static_cast<int>(std::lround(c.laser.resolutionDeg * 100))};
  l.remission = c.laser.remission;
  l.unit = c.laser.rangeUnit == "cm" ? drivers::lms291::Unit::kCm : drivers::lms291::Unit::kMm;
  return l;
}

// The tilt settings are the live drive's (tiltDriveConfigFrom): replay decodes TPDO1 with them.
drivers::logs::SensorReplayConfig sensorReplayConfig(const Config& c) { return {laserConfig(c), tiltDriveConfigFrom(c.tilt)}; }

fusion::SweepConfig sweepConfig(const Config& c) {
  fusion::SweepConfig s;
  s.tiltAxisOffset = Eigen::Vector3d(c.fusion.tiltAxisOffset[0], c.fusion.tiltAxisOffset[1], c.fusion.tiltAxisOffset[2]);
  s.tiltWindowS = c.fusion.tiltWindowMs * 1e-3;
  s.closeOnTilt = c.fusion.closeOnTilt;
  s.remissionFullScale = c.laser.remission ? c.laser.remissionFullScale : 1.0;
  // A nod takes (max - min) / speed plus the turn; twice that and 2 s more is no nod any longer
  // (10 s with the defaults): the tilt is parked or stuck and the open sweep is cut.
  s.maxSweepS = 2.0 * (c.tilt.maxDeg - c.tilt.minDeg) / c.tilt.speedDegS + 2.0;
  return s;
}

Eigen::Isometry3d laserToCamera(const Config& c) { return fusion::rigidFromRpyDeg(c.fusion.rotationRpyDeg, c.fusion.translation); }

drivers::v4l2::CameraConfig cameraConfig(const Config& c) {
  drivers::v4l2::CameraConfig v;
  v.device = c.camera.device;
  // The config loader accepted these values, so the parsers cannot fail here.
  v.format = drivers::v4l2::parseFormatChoice(c.camera.format).value_or(drivers::v4l2::FormatChoice::kYuyv);
  v.width = static_cast<std::uint32_t>(c.camera.width);
  v.height = static_cast<std::uint32_t>(c.camera.height);
  v.fps = c.camera.fps;
  v.buffers = static_cast<std::uint32_t>(c.camera.buffers);
  v.controls.exposure = drivers::v4l2::parseControlSetting(c.camera.exposure).value_or(drivers::v4l2::ControlSetting{});
  v.controls.gain = drivers::v4l2::parseControlSetting(c.camera.gain).value_or(drivers::v4l2::ControlSetting{});
  return v;
}

drivers::v4l2::FrameStreamTiming cameraTiming(const Config& c) {
  drivers::v4l2::FrameStreamTiming t;
  t.stallLimit = std::chrono::milliseconds(c.camera.stallMs);
  t.reconnectMax = std::chrono::milliseconds(static_cast<long>(c.camera.reconnectMaxS * 1000));
  return t;
}

ReplayRig replayRig(const std::filesystem::path& log, const Config& machine, const std::filesystem::path& configDir) {
  const drivers::logs::LogSource probe(log);
  const std::optional<drivers::logs::LogRig> rig = probe.rig();
  ReplayRig out;
  out.config = machine;
  if (rig) {
    const Config recorded = parseConfig(rig->configYaml, log.string() + ":fusedet.config");
    out.config.laser = recorded.laser;
    out.config.tilt = recorded.tilt;
    out.config.camera = recorded.camera;
    out.config.fusion = recorded.fusion;
    out.config.fusion.closeOnTilt = machine.fusion.closeOnTilt;  // how this machine closes sweeps, not the rig's
    out.origin = log.string() + " (metadata fusedet.config)";
  } else {
    out.origin = "the machine config (the log carries no fusedet.config)";
  }
  const std::string& calibration = out.config.camera.calibration;
  if (rig && calibration == "log:camera.yaml") {
    if (rig->cameraYaml.empty()) throw std::runtime_error(log.string() + ": fusedet.config has no camera.yaml");
    out.camera = fusion::parseCameraModel(rig->cameraYaml, log.string() + ":camera.yaml");
  } else {
    std::filesystem::path file = calibration;
    if (file.is_relative()) file = configDir / file;
    out.camera = fusion::readCameraModel(file);
  }
  return out;
}

}  // namespace fusedet::daemon
