// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/live/live_channels.h"

#include "fusedet/daemon/live/view_images.h"
#include "fusedet/daemon/stack_channels.h"
#include "fusedet/drivers/log/channels.h"

namespace fusedet::daemon::live {

namespace logs = drivers::logs;

namespace {

constexpr char kStatusSchema[] =
    R"({"title":"fusedet.Status","type":"object","properties":{"timestamp":{"type":"object","properties":{"sec":{"type":"integer"},)"
    R"("nsec":{"type":"integer"}}},"mode":{"type":"string"},"sensors":{"type":"array"},"pipeline":{"type":"object"},)"
    R"("latency_ms":{"type":"object"},"clients":{"type":"object"},"live":{"type":"object"}}})";

// A JPEG as the sensor logs' foxglove.CompressedImage (an MJPEG camera frame's encoding).
std::vector<std::uint8_t> compressedImage(std::vector<std::uint8_t> jpeg, const StackResult& r, int width, int height) {
  drivers::CameraFrame f;
  f.stamp = r.frameStamp;
  f.sequence = r.stackId;
  f.format = drivers::PixelFormat::kMjpeg;
  f.width = width;
  f.height = height;
  f.bytes = std::move(jpeg);
  return logs::encode(f);
}

}  // namespace

LiveChannels::LiveChannels(ChannelSettings settings) : settings_(std::move(settings)) {
  auto add = [this](std::string topic, logs::Schema schema, Kind kind, std::string layer = {}) {
    channels_.push_back({static_cast<std::uint32_t>(channels_.size() + 1), std::move(topic), std::string(logs::schemaName(schema)),
                         std::string(logs::schemaJson(schema))});
    entries_.push_back({kind, std::move(layer)});
  };
  add(logs::topic::kCameraCompressed, logs::Schema::kCompressedImage, Kind::kImage);
  add(logs::topic::kDetections, logs::Schema::kImageAnnotations, Kind::kAnnotations);
  add("/detections/scene", logs::Schema::kSceneUpdate, Kind::kDetectionScene);
  add(logs::topic::kSweep, logs::Schema::kPointCloud, Kind::kSweep);
  add(logs::topic::kTransforms, logs::Schema::kFrameTransform, Kind::kTransform);
  add(logs::topic::kCameraCalibration, logs::Schema::kCameraCalibration, Kind::kCalibration);
  add(logs::topic::kTrackScene, logs::Schema::kSceneUpdate, Kind::kTrackScene);
  add(logs::topic::kTracks, logs::Schema::kTracks, Kind::kTracks);
  for (const std::string& name : settings_.layers) add("/layers/" + name, logs::Schema::kCompressedImage, Kind::kLayer, name);
  statusId_ = static_cast<std::uint32_t>(channels_.size() + 1);
  channels_.push_back({statusId_, "/status", "fusedet.Status", kStatusSchema});
  entries_.push_back({Kind::kStatus, {}});
}

std::optional<std::vector<std::uint8_t>> LiveChannels::encode(std::uint32_t id, const StackResult& r) const {
  if (id == 0 || id > entries_.size()) return std::nullopt;
  const Entry& e = entries_[id - 1];
  const fusion::PinholeProjection& p = settings_.projection;
  switch (e.kind) {
    case Kind::kImage: {
      if (!r.view) return std::nullopt;
      auto jpeg = colourJpeg(r.view->layers);
      if (!jpeg) return std::nullopt;
      return compressedImage(std::move(*jpeg), r, r.view->layers.width(), r.view->layers.height());
    }
    case Kind::kAnnotations: return logs::encode(detectionAnnotations(r));
    case Kind::kDetectionScene: return logs::encode(detectionScene(r, p.K, settings_.lifetimeS));
    case Kind::kSweep:
      if (!r.view) return std::nullopt;
      return logs::encode(sweepCloud(r.frameStamp, r.view->sweep));
    case Kind::kTransform: return logs::encode(frameTransform(r.frameStamp, kBaseFrame, kCameraFrame, p.sweepToCamera.inverse()));
    case Kind::kCalibration: {
      fusion::CameraModel camera;
      camera.width = p.width;
      camera.height = p.height;
      camera.K = p.K;
      return logs::encode(cameraCalibration(r.frameStamp, camera));
    }
    case Kind::kTrackScene: return logs::encode(trackScene(r, settings_.lifetimeS));
    case Kind::kTracks: return tracksMessage(r);
    case Kind::kLayer: {
      const Layer* l = r.view ? r.view->layers.find(e.layer) : nullptr;
      if (!l) return std::nullopt;
      return compressedImage(layerJpeg(*l), r, l->width(), l->height());
    }
    case Kind::kStatus: return std::nullopt;
  }
  return std::nullopt;
}

std::vector<std::uint8_t> LiveChannels::encodeStatus(nlohmann::json status, Stamp t) const {
  const logs::SecNsec s = logs::secNsec(t);
  status["timestamp"] = {{"sec", s.sec}, {"nsec", s.nsec}};
  const std::string text = status.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace);
  return {text.begin(), text.end()};
}

}  // namespace fusedet::daemon::live
