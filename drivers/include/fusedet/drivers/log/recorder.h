// SPDX-License-Identifier: Apache-2.0
#pragma once
// Recorder: one MCAP sensor log written from several driver threads (the drivers' recording
// hooks call record()). Channels are created on first use with the topics and schemas of
// channels.h; log time = publish time = the message's sensor stamp.
//
// Crash safety: a background thread closes the open chunk every `flushEvery`, so a crash or a
// power cut loses at most that much (plus what the OS had not written). A write error (disk
// full) stops the recording - later record() calls do nothing - and is kept in error(); it never
// throws into a driver thread.

#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "fusedet/drivers/log/channels.h"
#include "fusedet/drivers/log/mcap_writer.h"

namespace fusedet::drivers::logs {

class Recorder {
 public:
  // Throws mcap::McapError when the file cannot be created. flushEvery 0 = no flush thread
  // (offline writers such as synth-log; chunks close by size and log-time span only).
  explicit Recorder(const std::filesystem::path& path, mcap::WriterOptions options = {},
                    std::chrono::milliseconds flushEvery = std::chrono::milliseconds(1000));
  ~Recorder();
  Recorder(const Recorder&) = delete;
  Recorder& operator=(const Recorder&) = delete;

  // The rig: config.yaml (fusedet.yaml format) and camera.yaml (ROS camera_info) under
  // metadata "fusedet.config" (channels.h), plus any extra entries.
  void setRig(const std::string& configYaml, const std::string& cameraYaml, const mcap::StringMap& extra = {});
  void addMetadata(const std::string& name, const mcap::StringMap& entries);

  void record(const SerialChunk& m);
  void record(const CanMessage& m);
  void record(const CameraFrame& m);
  void record(const LaserScan& m);
  void record(const TiltSample& m);
  void record(const PointCloudMessage& m);
  void record(const AnnotationsMessage& m);
  void record(const TransformMessage& m);
  void record(const CameraCalibrationMessage& m);
  // A message already encoded for `topic` (its JSON bytes), e.g. copied from another log.
  void recordEncoded(const std::string& topic, Schema schema, Stamp stamp, const std::vector<std::uint8_t>& json);

  // Closes the open chunk now.
  void flush();
  // Writes the summary and closes the file; rethrows a write error as McapError. Idempotent.
  void close();

  std::uint64_t messages() const;
  std::string error() const;  // empty while healthy

 private:
  void write(const std::string& topic, Schema schema, Stamp stamp, const std::vector<std::uint8_t>& data);
  void flushLoop(std::chrono::milliseconds every);

  mutable std::mutex mutex_;
  std::unique_ptr<mcap::McapWriter> writer_;
  std::map<Schema, std::uint16_t> schemas_;
  std::map<std::string, std::uint16_t> channels_;
  std::string error_;
  bool closed_ = false;
  std::condition_variable wake_;
  std::thread flusher_;
};

}  // namespace fusedet::drivers::logs
