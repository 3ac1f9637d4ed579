// SPDX-License-Identifier: Apache-2.0
#pragma once
// synth-log: a realistic raw sensor log (docs/log-format.md) made from real KITTI frames, or
// from a procedural scene when no KITTI data is given.
//
// The rig: a SICK LMS 291 (100 deg / 1 deg, range + remission telegrams F5, cm units, 500 kbaud)
// on a nodding unit driven by a CiA 402 motor (CAN node 5), and the camera. For KITTI the laser
// base frame is the Velodyne frame and the camera is KITTI's rectified colour camera 2, so
// `fusion.laser_to_camera` is KITTI's velo -> cam2 transform.
// - The tilt unit: canopen::TiltDrive (the live master) and issue 11's CiA 402 motor simulator
//   on the in-process bus in simulated time (sim::runNodSimulation): NMT reset and boot-up, SDO
//   configuration (TPDO1 = position + statusword, profile position mode, heartbeat), NMT start,
//   enable, a move to the nearer end, then one sweep per frame; SYNC every 10 ms, TPDO1 answers,
//   heartbeats, the set-point SDO handshakes, and the stop sequence at the end. Every frame either
//   node sent goes into the log at its bus time.
// - Each KITTI frame is one sweep of the nodding unit (min -> max or back); the scene is taken
//   as standing still during the sweep (a time lapse: sweeps take ~1.5 s, KITTI frames are
//   0.3 s apart). Laser and camera start when the first sweep starts (before it, during the
//   drive's start-up, the log holds CAN traffic only).
// - Every beam: time = scan start + beam x 1/(360 x 75) s (the mirror), tilt = the simulated
//   motor's actual position at that time (1 ms steps, interpolated), direction from scan angle
//   and tilt (SweepAssembler's geometry);
//   range and remission from the nearest Velodyne return along that ray (PointRayCaster,
//   angular tolerance `toleranceDeg`), quantised to cm and remission x 1000.
// - Telegram bytes: lms291::encode of F5 telegrams, one per mirror rotation (75 Hz), sent from
//   the scan's start time at 500 kbaud (10 bits/byte), read in 64-byte pieces stamped when their
//   last byte arrived (what the driver's stamp model inverts).
// - Camera: YUYV frames at `cameraFps` showing the KITTI image of the stroke in progress.
// The rig is written as metadata "fusedet.config" (config.yaml + camera.yaml): replaying the log
// with that configuration reproduces the geometry used here.

#include <filesystem>
#include <string>
#include <vector>

#include "fusedet/core/stamp.h"
#include "fusedet/drivers/canopen/tilt_drive.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {

struct SynthOptions {
  std::filesystem::path kitti;  // KITTI-layout directory; empty = procedural scene
  int frames = 6;               // strokes (one KITTI frame each)
  int first = -1;               // index into listKittiFrames; -1 = first frame of the drive's last third
  double cameraFps = 5;
  double toleranceDeg = 0.4;    // beam <-> Velodyne point angular tolerance
  Stamp start{1'000'000'000'000};  // stamp of the first message (CLOCK_MONOTONIC-like)
};

// The synthetic device's settings (what config.yaml says).
struct SynthRig {
  int baud = 500000;
  int angleDeg = 100, resolutionCdeg = 100;
  double remissionFullScale = 1000;
  drivers::canopen::TiltDriveConfig tilt;  // set by the constructor: node 5, -3 .. 16 deg at 15 deg/s
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
  std::vector<Stamp> strokeStart;     // per stroke: the motor leaves one end
  Stamp end{};                        // the last stroke reached its end
  double strokeS = 0;                 // mean period from one stroke's start to the next
  double startupS = 0;                // first CAN frame -> first stroke (bring-up, move to the end)
  std::uint64_t scans = 0, beams = 0, hits = 0, serialBytes = 0, serialChunks = 0, canFrames = 0, cameraFrames = 0;
  std::uint64_t tpdos = 0, sdoRequests = 0;  // the motor simulator's counters
  double seconds = 0;                 // log duration
  SynthRig rig;
};

// Writes the log to `out`. Throws std::runtime_error (bad KITTI directory, frame range) or
// mcap::McapError (cannot write).
SynthReport synthesizeLog(const SynthOptions& options, const std::filesystem::path& out);

}  // namespace fusedet::fusion
