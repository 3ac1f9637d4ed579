#include "fusedet/daemon/rig.h"

#include <cmath>

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

drivers::logs::TiltDecoderConfig tiltUnits(const Config& c) {
  return drivers::logs::TiltDecoderConfig{c.tilt.nodeId, c.tilt.countsPerRev, c.tilt.gearRatio, c.tilt.zeroOffsetCounts};
}

drivers::logs::SensorReplayConfig sensorReplayConfig(const Config& c) { return {laserConfig(c), tiltUnits(c)}; }

fusion::SweepConfig sweepConfig(const Config& c) {
  fusion::SweepConfig s;
  s.tiltAxisOffset = Eigen::Vector3d(c.fusion.tiltAxisOffset[0], c.fusion.tiltAxisOffset[1], c.fusion.tiltAxisOffset[2]);
  s.tiltWindowS = c.fusion.tiltWindowMs * 1e-3;
  s.remissionFullScale = c.laser.remission ? c.laser.remissionFullScale : 1.0;
  return s;
}

Eigen::Isometry3d laserToCamera(const Config& c) { return fusion::rigidFromRpyDeg(c.fusion.rotationRpyDeg, c.fusion.translation); }

}  // namespace fusedet::daemon
