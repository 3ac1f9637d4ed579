// SPDX-License-Identifier: Apache-2.0
// Writes a sensor log with known content through logs::Recorder (every channel kind, several
// chunks) and prints what it wrote as JSON, so an independent reader (mcap_core_reader.cjs,
// @mcap/core from npm) can check the file against the writer's intent, not against our reader.
// Usage: sample_log_writer OUT.mcap > expected.json

#include <cstdio>
#include <nlohmann/json.hpp>

#include "fusedet/drivers/log/base64.h"
#include "fusedet/drivers/log/recorder.h"

using namespace fusedet;
using namespace fusedet::drivers;
using namespace fusedet::drivers::logs;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: sample_log_writer OUT.mcap\n");
    return 2;
  }
  mcap::WriterOptions options;
  options.chunkBytes = 16 * 1024;  // several chunks
  Recorder rec(argv[1], options, std::chrono::milliseconds(0));
  const std::string config = "version: 1\nlaser:\n  baud: 500000\n";
  rec.setRig(config, "image_width: 8\nimage_height: 2\n", {{"source", "sample_log_writer"}});
  nlohmann::json counts;
  const std::int64_t t0 = 5'000'000'000;
  std::vector<std::uint8_t> firstSerial;
  for (std::int64_t i = 0; i < 400; ++i) {  // 400 serial chunks, 2 ms apart, 0..63 bytes each
    SerialChunk s{Stamp{t0 + i * 2'000'000}, "/dev/ttyUSB0", 500000, {}};
    for (std::int64_t k = 0; k < i % 64; ++k) s.bytes.push_back(static_cast<std::uint8_t>(i * 7 + k));
    if (i == 1) firstSerial = s.bytes;
    rec.record(s);
  }
  counts[topic::kLaserRaw] = 400;
  for (std::int64_t i = 0; i < 300; ++i) {  // SYNC, TPDO1 with position i, heartbeat every 10th
    rec.record(CanMessage{Stamp{t0 + i * 10'000'000}, "can0", 0x080, false, false, false, {}});
    rec.record(CanMessage{Stamp{t0 + i * 10'000'000 + 200'000}, "can0", 0x185, false, false, false,
                          {static_cast<std::uint8_t>(i), static_cast<std::uint8_t>(i >> 8), 0, 0}});
    if (i % 10 == 0) rec.record(CanMessage{Stamp{t0 + i * 10'000'000 + 500'000}, "can0", 0x705, false, false, false, {0x05}});
  }
  counts[topic::kCan] = 300 * 2 + 30;
  for (std::int64_t i = 0; i < 12; ++i) {
    CameraFrame f;
    f.stamp = Stamp{t0 + i * 66'000'000};
    f.sequence = static_cast<std::uint64_t>(i);
    f.width = 8;
    f.height = 2;
    f.stride = 16;
    f.format = PixelFormat::kYuyv;
    f.bytes.assign(32, static_cast<std::uint8_t>(i));
    rec.record(f);
  }
  counts[topic::kCameraRaw] = 12;
  for (std::int64_t i = 0; i < 50; ++i) {
    LaserScan s;
    s.stamp = Stamp{t0 + i * 13'333'333};
    s.sequence = static_cast<std::uint64_t>(i);
    s.startAngle = 40 * M_PI / 180;
    s.angleStep = M_PI / 180;
    s.ranges.assign(101, 2.5f + static_cast<float>(i));
    rec.record(s);
    rec.record(TiltSample{s.stamp, 0.001 * i, 0.26});
  }
  counts[topic::kLaserScan] = 50;
  counts[topic::kTilt] = 50;
  rec.record(PointCloudMessage{Stamp{t0}, "laser_base", {{1, 2, 3, 0.5f}, {4, 5, 6, 1}}});
  counts[topic::kSweep] = 1;
  rec.record(AnnotationsMessage{Stamp{t0}, {{"car", 0.9, 10, 20, 30, 40}}});
  counts[topic::kDetections] = 1;
  rec.record(TransformMessage{Stamp{t0}, "laser_base", "camera", {0.1, 0.2, 0.3}, {0, 0, 0, 1}});
  counts[topic::kTransforms] = 1;
  CameraCalibrationMessage calibration;
  calibration.stamp = Stamp{t0};
  calibration.width = 8;
  calibration.height = 2;
  calibration.D = {0.1, -0.2, 0, 0, 0};
  calibration.K = {5, 0, 4, 0, 5, 1, 0, 0, 1};
  calibration.P = {5, 0, 4, 0, 0, 5, 1, 0, 0, 0, 1, 0};
  rec.record(calibration);
  counts[topic::kCameraCalibration] = 1;
  CameraFrame jpeg;  // an MJPEG buffer: its bytes pass through unchanged
  jpeg.stamp = Stamp{t0 + 1'000'000};
  jpeg.format = PixelFormat::kMjpeg;
  jpeg.width = 8;
  jpeg.height = 2;
  jpeg.bytes = {0xFF, 0xD8, 0xFF, 0xD9};
  rec.record(jpeg);
  counts[topic::kCameraCompressed] = 1;
  rec.close();
  int total = 0;
  for (const auto& [k, v] : counts.items()) total += v.get<int>();
  const nlohmann::json expected{{"counts", counts},
                                {"total", total},
                                {"second_serial_base64", base64Encode(firstSerial)},
                                {"config_yaml", config},
                                {"first_time_ns", std::to_string(t0)},
                                {"schemas", {{topic::kLaserRaw, "fusedet.RawSerial"}, {topic::kCan, "fusedet.CanFrame"},
                                             {topic::kCameraRaw, "foxglove.RawImage"}, {topic::kLaserScan, "foxglove.LaserScan"},
                                             {topic::kSweep, "foxglove.PointCloud"}, {topic::kDetections, "foxglove.ImageAnnotations"},
                                             {topic::kTransforms, "foxglove.FrameTransform"}, {topic::kTilt, "fusedet.TiltSample"},
                                             {topic::kCameraCalibration, "foxglove.CameraCalibration"},
                                             {topic::kCameraCompressed, "foxglove.CompressedImage"}}}};
  std::printf("%s\n", expected.dump().c_str());
  return 0;
}
