// SPDX-License-Identifier: Apache-2.0
#pragma once
// The channels the live view advertises and each one's message for a stack (docs/live-view.md).
// Topics and schemas are the sensor logs' (docs/log-format.md): a Foxglove layout made for a log
// shows the live view too. The messages come from daemon/stack_channels.h and
// drivers/log/channels.h, the code `fusedet log derive` records with.
//   /camera/compressed  foxglove.CompressedImage   the stack's camera image (undistorted: the boxes' grid), JPEG
//   /detections         foxglove.ImageAnnotations  a box and a label per detection
//   /detections/scene   foxglove.SceneUpdate       a 3D box per located detection, in laser_base
//   /sweep/points       foxglove.PointCloud        the stack's sweep in laser_base
//   /tf                 foxglove.FrameTransform    laser_base -> camera
//   /camera/calibration foxglove.CameraCalibration the undistorted image's pinhole
//   /tracks/scene       foxglove.SceneUpdate       one entity per live track
//   /tracks             fusedet.Tracks             the socket's tracks line
//   /layers/NAME        foxglove.CompressedImage   each layer of live.layers in false colour, JPEG
//   /status             fusedet.Status             the socket's status reply, once a second

#include <cstdint>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/daemon/live/foxglove_protocol.h"
#include "fusedet/daemon/pipeline.h"
#include "fusedet/fusion/projection.h"

namespace fusedet::daemon::live {

struct ChannelSettings {
  fusion::PinholeProjection projection;  // the fuser's: K of the undistorted image, sweepToCamera
  double lifetimeS = 1.0;                // scene entities expire (the tracker's max_coast_s)
  std::vector<std::string> layers;       // live.layers
};

class LiveChannels {
 public:
  explicit LiveChannels(ChannelSettings settings);

  const std::vector<Channel>& channels() const { return channels_; }
  std::uint32_t statusChannel() const { return statusId_; }
  // Channel `id`'s JSON message for one stack; nothing when the stack has nothing for it (no
  // view kept, a layer it lacks) or `id` is the status channel or unknown.
  std::optional<std::vector<std::uint8_t>> encode(std::uint32_t id, const StackResult& result) const;
  // The /status message: the status reply with a timestamp.
  std::vector<std::uint8_t> encodeStatus(nlohmann::json status, Stamp t) const;

 private:
  enum class Kind { kImage, kAnnotations, kDetectionScene, kSweep, kTransform, kCalibration, kTrackScene, kTracks, kLayer, kStatus };
  struct Entry {
    Kind kind;
    std::string layer;  // kLayer
  };
  ChannelSettings settings_;
  std::vector<Channel> channels_;
  std::vector<Entry> entries_;  // by channel id - 1
  std::uint32_t statusId_ = 0;
};

}  // namespace fusedet::daemon::live
