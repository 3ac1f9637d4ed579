// SPDX-License-Identifier: Apache-2.0
#pragma once
// What fusedet sensor logs carry: topics, their schemas (JSON Schema, messages JSON-encoded) and
// the codecs between driver messages and those JSON messages. Documented in docs/log-format.md.
//
// Raw streams (what replay feeds into the live decoders):
//   /lms291/raw      fusedet.RawSerial       bytes as read from the serial port, stamped at the read
//   /tilt/can        fusedet.CanFrame        every CAN frame seen on the tilt motor's bus
//   /camera/image    foxglove.RawImage       raw camera buffers (YUYV, BGR, GRAY)
//   /camera/compressed foxglove.CompressedImage  MJPEG buffers
// Decoded and derived data (for viewers; replay recomputes them from the raw streams):
//   /lms291/scan     foxglove.LaserScan      /tilt/sample  fusedet.TiltSample
//   /sweep/points    foxglove.PointCloud     /detections   foxglove.ImageAnnotations
//   /tf              foxglove.FrameTransform  /camera/calibration foxglove.CameraCalibration
//   /tracks          fusedet.Tracks          /tracks/scene foxglove.SceneUpdate
// Metadata record "fusedet.config": "config.yaml" (fusedet.yaml format), "camera.yaml" (ROS
// camera_info); see docs/log-format.md.

#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::logs {

namespace topic {
inline constexpr char kLaserRaw[] = "/lms291/raw";
inline constexpr char kCan[] = "/tilt/can";
inline constexpr char kCameraRaw[] = "/camera/image";
inline constexpr char kCameraCompressed[] = "/camera/compressed";
inline constexpr char kLaserScan[] = "/lms291/scan";
inline constexpr char kTilt[] = "/tilt/sample";
inline constexpr char kSweep[] = "/sweep/points";
inline constexpr char kDetections[] = "/detections";
inline constexpr char kTransforms[] = "/tf";
inline constexpr char kCameraCalibration[] = "/camera/calibration";
inline constexpr char kTracks[] = "/tracks";           // the socket's tracks line per stack
inline constexpr char kTrackScene[] = "/tracks/scene";  // one 3D entity per live track
}  // namespace topic

// Metadata record names and keys.
inline constexpr char kConfigMetadata[] = "fusedet.config";
inline constexpr char kConfigYamlKey[] = "config.yaml";
inline constexpr char kCameraYamlKey[] = "camera.yaml";
inline constexpr char kRecordingMetadata[] = "fusedet.recording";

enum class Schema {
  kRawSerial, kCanFrame, kRawImage, kCompressedImage, kLaserScan, kTiltSample, kPointCloud,
  kImageAnnotations, kFrameTransform, kCameraCalibration, kTracks, kSceneUpdate,
};
inline constexpr std::array kAllSchemas = {Schema::kRawSerial, Schema::kCanFrame, Schema::kRawImage,
                                           Schema::kCompressedImage, Schema::kLaserScan, Schema::kTiltSample,
                                           Schema::kPointCloud, Schema::kImageAnnotations, Schema::kFrameTransform,
                                           Schema::kCameraCalibration, Schema::kTracks, Schema::kSceneUpdate};
std::string_view schemaName(Schema s);  // "fusedet.RawSerial", "foxglove.RawImage", ...
std::string_view schemaJson(Schema s);  // its JSON Schema text
std::optional<Schema> schemaByName(std::string_view name);

// Raw bytes of a serial port as one read returned them.
struct SerialChunk {
  Stamp stamp;          // when the read returned (its last byte had arrived)
  std::string device;   // port path or role name
  int baud = 0;         // line speed at the time
  std::vector<std::uint8_t> bytes;
};

// One classic CAN frame (or SocketCAN error frame) as received or sent on the bus.
struct CanMessage {
  Stamp stamp;
  std::string interface;  // "can0", "inprocess", ...
  std::uint32_t id = 0;
  bool extended = false, rtr = false, error = false;
  std::vector<std::uint8_t> data;  // 0..8 bytes
};

// A 3D point cloud (a sweep) in a named frame: x y z [m], remission [0, 1], float32 each.
struct PointCloudMessage {
  Stamp stamp;
  std::string frame = "laser_base";
  std::vector<std::array<float, 4>> points;
};

// One detection drawn on the camera image.
struct Annotation {
  std::string label;
  double score = 0;
  double x = 0, y = 0, width = 0, height = 0;  // [px]
};
struct AnnotationsMessage {
  Stamp stamp;
  std::vector<Annotation> boxes;
};

struct TransformMessage {
  Stamp stamp;
  std::string parent, child;
  std::array<double, 3> translation{};
  std::array<double, 4> rotation{0, 0, 0, 1};  // quaternion x y z w
};

// The camera's intrinsics for viewers (ROS camera_info conventions): Foxglove projects the sweep
// into the image and places the image in 3D with it.
struct CameraCalibrationMessage {
  Stamp stamp;
  std::string frame = "camera";
  int width = 0, height = 0;
  std::string distortionModel = "plumb_bob";
  std::vector<double> D;                             // distortion coefficients
  std::array<double, 9> K{};                         // intrinsic matrix, row-major
  std::array<double, 9> R{1, 0, 0, 0, 1, 0, 0, 0, 1};  // rectification
  std::array<double, 12> P{};                        // projection matrix, row-major
};

// A stamp as the messages' "timestamp" carries it: whole seconds and nanoseconds in [0, 1e9).
struct SecNsec {
  std::int64_t sec = 0, nsec = 0;
};
SecNsec secNsec(Stamp s);

// Objects in 3D for a viewer (foxglove.SceneUpdate): one entity per object, drawn as a sphere (or a box) with
// a text above it and, when it moves, an arrow along its velocity. Every message first deletes
// every entity the channel drew before (SceneEntityDeletion ALL), so an object absent from a
// message disappears; each entity also expires after `lifetimeS` (no further message needed).
struct SceneObject {
  std::string id;                               // entity id, unique within a message
  std::string text;                             // drawn above it
  std::array<double, 3> position{};             // [m] in the message's frame
  std::array<double, 3> velocity{};             // [m/s]; the arrow is 1 s of travel long
  double diameter = 0.5;                        // of the sphere [m]
  std::array<double, 4> colour{1, 1, 1, 1};     // r g b a in [0, 1]
  std::vector<std::pair<std::string, std::string>> metadata;  // key/value pairs a viewer lists
  std::array<double, 3> boxSize{};              // non-zero: drawn as a box of this size [m] (x y z) instead of a sphere
};
struct SceneUpdateMessage {
  Stamp stamp;
  std::string frame = "laser_base";
  double lifetimeS = 0;  // 0 = until deleted
  std::vector<SceneObject> objects;
};

// Encoders: the JSON message bytes of each channel (fusedet.Tracks is the daemon's tracks line,
// fusedet/daemon/stack_channels.h).
std::vector<std::uint8_t> encode(const SerialChunk& m);
std::vector<std::uint8_t> encode(const CanMessage& m);
std::vector<std::uint8_t> encode(const CameraFrame& m);  // RawImage, or CompressedImage for MJPEG
std::vector<std::uint8_t> encode(const LaserScan& m);
std::vector<std::uint8_t> encode(const TiltSample& m);
std::vector<std::uint8_t> encode(const PointCloudMessage& m);
std::vector<std::uint8_t> encode(const AnnotationsMessage& m);
std::vector<std::uint8_t> encode(const TransformMessage& m);
std::vector<std::uint8_t> encode(const CameraCalibrationMessage& m);
std::vector<std::uint8_t> encode(const SceneUpdateMessage& m);
Schema schemaOf(const CameraFrame& m);

// Decoders: errors (std::errc::bad_message) name the field that is missing or malformed.
Result<SerialChunk> decodeSerial(std::span<const std::uint8_t> json);
Result<CanMessage> decodeCan(std::span<const std::uint8_t> json);
Result<CameraFrame> decodeCamera(std::span<const std::uint8_t> json);  // RawImage or CompressedImage
Result<LaserScan> decodeLaserScan(std::span<const std::uint8_t> json);
Result<TiltSample> decodeTilt(std::span<const std::uint8_t> json);
Result<PointCloudMessage> decodePointCloud(std::span<const std::uint8_t> json);

}  // namespace fusedet::drivers::logs
