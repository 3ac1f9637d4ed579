// SPDX-License-Identifier: Apache-2.0
#pragma once
// deriveLog: a sensor log made viewable - the raw streams of IN copied to OUT, plus the channels
// a person needs to see it in Foxglove (docs/log-format.md, "Derived channels"), computed by
// replaying IN through the live decoders, the sweep assembly, the fusion and the detectors,
// configured only from the rig IN carries (metadata fusedet.config):
//   /lms291/scan         foxglove.LaserScan          every decoded scan, frame `laser`
//   /tilt/sample         fusedet.TiltSample          every decoded tilt sample
//   /tf                  foxglove.FrameTransform     laser_base -> laser at every tilt sample (the nod),
//                                                    laser_base -> camera (the extrinsics) with every frame
//   /camera/calibration  foxglove.CameraCalibration  with every camera frame
//   /sweep/points        foxglove.PointCloud         every assembled sweep, frame `laser_base`
//   /detections          foxglove.ImageAnnotations   per fused stack, stamped like its camera frame
//   /tracks              fusedet.Tracks              per stack: the socket's tracks line (fusedet/daemon/stack_channels.h)
//   /tracks/scene        foxglove.SceneUpdate        per stack: one 3D entity per live track
// The stacks (detections, 3D positions, tracks) are the daemon's pipeline run on IN
// (fusedet/daemon/offline_replay.h) with the rig's config and the given models: what fusedetd would send.
// Derived channels IN already had are not copied (they are computed again).

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

namespace fusedet::sensor_logs {

struct DeriveOptions {
  std::vector<std::filesystem::path> models;  // model files (*.json); none = no /detections
};

struct DeriveReport {
  std::uint64_t copied = 0;         // raw messages copied
  std::uint64_t dropped = 0;        // derived messages of IN not copied
  std::uint64_t scans = 0, tiltSamples = 0, frames = 0;
  std::uint64_t sweeps = 0, points = 0;
  std::uint64_t stacks = 0;          // sweeps paired with a camera frame; with models: stacks detected
  std::uint64_t detections = 0;
  std::uint64_t trackMessages = 0;   // on /tracks and /tracks/scene
  std::uint64_t transforms = 0;
  std::vector<std::string> classes;  // of the models
  bool calibrated = false;           // IN had a camera calibration (else no stacks, no detections)
};

// Throws mcap::McapError (unreadable IN, OUT not writable), std::runtime_error (IN without a
// rig, a model file that does not load).
DeriveReport deriveLog(const std::filesystem::path& in, const std::filesystem::path& out, const DeriveOptions& options);

}  // namespace fusedet::sensor_logs
