// SPDX-License-Identifier: Apache-2.0
#pragma once
// A stack result as Foxglove channel messages (docs/log-format.md): what `fusedet log derive`
// records and what the live view (daemon/live/) sends, built here once. The JSON bytes come from
// drivers/log/channels.h's encoders.
//   /sweep/points  foxglove.PointCloud   a sweep in laser_base: x y z remission, float32
//   /detections    foxglove.ImageAnnotations  a box and a label per detection, on the camera image
//   /detections/scene foxglove.SceneUpdate  a box per located detection in laser_base
//   /tracks        fusedet.Tracks        the socket's `tracks` line (fusedet/daemon/protocol.h tracksToJson) plus
//                                        the log timestamp (the stack's camera frame)
//   /tracks/scene  foxglove.SceneUpdate  one entity per live track in frame laser_base (the robot
//                                        frame the tracker works in): id "track-N", a sphere of
//                                        2 sigma, an arrow along the velocity, a text, metadata
//   /tf            foxglove.FrameTransform  laser_base -> camera (the extrinsics), laser_base -> laser (the tilt)
//   /camera/calibration foxglove.CameraCalibration  the camera's intrinsics
// In the scene a confirmed, detected track is drawn in its class colour, a coasting one (not
// detected in this stack) in that colour at 30 % opacity, a tentative one grey; every message
// replaces the previous one's entities and each entity expires after `lifetimeS`.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "fusedet/daemon/pipeline.h"
#include "fusedet/drivers/log/channels.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/sweep.h"

namespace fusedet::daemon {

// Frame ids of the messages: the sweeps' frame (the nodding unit's fixed base), the scanner
// (turned by the tilt) and the camera.
inline constexpr char kBaseFrame[] = "laser_base";
inline constexpr char kLaserFrame[] = "laser";
inline constexpr char kCameraFrame[] = "camera";

// The /sweep/points message: a sweep's points (x y z remission) in laser_base.
drivers::logs::PointCloudMessage sweepCloud(Stamp t, const std::vector<fusion::SweepPoint>& points);

// The /detections message: one box and label per detection, stamped with the camera frame.
drivers::logs::AnnotationsMessage detectionAnnotations(const StackResult& result);

// The JSON bytes of one /tracks message.
std::vector<std::uint8_t> tracksMessage(const StackResult& result);

// The /tracks/scene message. lifetimeS: the tracker's max_coast_s - a track whose last detection
// is older has died, so an entity never outlives its track when no further stack comes.
drivers::logs::SceneUpdateMessage trackScene(const StackResult& result, double lifetimeS);

// The /detections/scene message: a box per located detection in laser_base (a detection without
// a position is not drawn), sized from its image box at its range (width = box width / fx *
// range, the same depth; height = box height / fy * range) in its class colour, with its class,
// score and range as text; K: the pinhole of the stack's (undistorted) image. Entities expire
// after lifetimeS.
drivers::logs::SceneUpdateMessage detectionScene(const StackResult& result, const Eigen::Matrix3d& K, double lifetimeS);

// A /tf message: `child` placed in `parent` (childInParent maps child coordinates to parent's).
drivers::logs::TransformMessage frameTransform(Stamp t, const std::string& parent, const std::string& child,
                                               const Eigen::Isometry3d& childInParent);

// The /camera/calibration message of a camera model (P = [K | 0]).
drivers::logs::CameraCalibrationMessage cameraCalibration(Stamp t, const fusion::CameraModel& camera);

}  // namespace fusedet::daemon
