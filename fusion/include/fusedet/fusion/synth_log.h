#pragma once
// synth-log: a realistic raw sensor log (docs/log-format.md) made from real KITTI frames, or
// from a procedural scene when no KITTI data is given.
//
// The rig: a SICK LMS 291 (100 deg / 1 deg, range + remission telegrams F5, cm units, 500 kbaud)
// on a nodding unit driven by a CiA 402 motor (CAN node 5), and the camera. For KITTI the laser
// base frame is the Velodyne frame and the camera is KITTI's rectified colour camera 2, so
// `fusion.laser_to_camera` is KITTI's velo -> cam2 transform.
// - Each KITTI frame is one stroke of the nodding unit (min -> max or back); the scene is taken
//   as standing still during the stroke (a time lapse: strokes take ~1.4 s, KITTI frames are
//   0.3 s apart).
// - Every beam: time = scan start + beam x 1/(360 x 75) s (the mirror), tilt from the motion
//   profile at that time, direction from scan angle and tilt (SweepAssembler's geometry);
//   range and remission from the nearest Velodyne return along that ray (PointRayCaster,
//   angular tolerance `toleranceDeg`), quantised to cm and remission x 1000.
// - Telegram bytes: lms291::encode of F5 telegrams, one per mirror rotation (75 Hz), sent from
//   the scan's start time at 500 kbaud (10 bits/byte), read in 64-byte pieces stamped when their
//   last byte arrived (what the driver's stamp model inverts).
// - CAN: SYNC every 10 ms, TPDO1 (position actual value, counts) 0.2 ms after each SYNC with the
//   position sampled at the SYNC, heartbeat (operational) every 100 ms.
// - Camera: YUYV frames at `cameraFps` showing the KITTI image of the stroke in progress.
// The rig is written as metadata "fusedet.config" (config.yaml + camera.yaml): replaying the log
// with that configuration reproduces the geometry used here.

#include <filesystem>
#include <string>
#include <vector>

#include "fusedet/core/stamp.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/nod_profile.h"

namespace fusedet::fusion {

struct SynthOptions {
  std::filesystem::path kitti;  // KITTI-layout directory; empty = procedural scene
  int frames = 6;               // strokes (one KITTI frame each)
  int first = -1;               // index into listKittiFrames; -1 = first frame of the held-back last third
  double cameraFps = 5;
  double toleranceDeg = 0.4;    // beam <-> Velodyne point angular tolerance
  Stamp start{1'000'000'000'000};  // stamp of the first message (CLOCK_MONOTONIC-like)
};

// The synthetic device's settings (what config.yaml says).
struct SynthRig {
  int baud = 500000;
  int angleDeg = 100, resolutionCdeg = 100;
  double remissionFullScale = 1000;
  NodProfile nod;  // set by the constructor: -3 .. 16 deg, 15 deg/s, 150 deg/s^2
  int nodeId = 5, countsPerRev = 4096;
  double gearRatio = 50;
  double syncPeriodS = 0.010, tpdoDelayS = 0.0002, heartbeatS = 0.100;
  Eigen::Vector3d tiltAxisOffset{0, 0, 0.05};
  CameraModel camera;
  Eigen::Isometry3d laserToCamera = Eigen::Isometry3d::Identity();
  double cameraFps = 5;

  SynthRig();
  std::string configYaml() const;  // config/fusedet.yaml format: laser, tilt, camera, fusion
  std::string cameraYaml() const;  // ROS camera_info
};

struct SynthReport {
  std::string scene;                  // "kitti <dir>" or "procedural"
  std::vector<std::string> frameIds;  // per stroke: the KITTI frame id (procedural: "procedural-N")
  std::vector<Stamp> strokeStart;     // per stroke
  double strokeS = 0;
  std::uint64_t scans = 0, beams = 0, hits = 0, serialBytes = 0, serialChunks = 0, canFrames = 0, cameraFrames = 0;
  double seconds = 0;                 // log duration
  SynthRig rig;
};

// Writes the log to `out`. Throws std::runtime_error (bad KITTI directory, frame range) or
// mcap::McapError (cannot write).
SynthReport synthesizeLog(const SynthOptions& options, const std::filesystem::path& out);

}  // namespace fusedet::fusion
