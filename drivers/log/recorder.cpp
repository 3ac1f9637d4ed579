// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/recorder.h"

namespace fusedet::drivers::logs {

Recorder::Recorder(const std::filesystem::path& path, mcap::WriterOptions options, std::chrono::milliseconds flushEvery)
    : writer_(std::make_unique<mcap::McapWriter>(path, std::move(options))) {
  if (flushEvery.count() > 0) flusher_ = std::thread([this, flushEvery] { flushLoop(flushEvery); });
}

Recorder::~Recorder() {
  try {
    close();
  } catch (const std::exception&) {  // NOLINT(bugprone-empty-catch): reported by close() to those who call it
  }
}

void Recorder::flushLoop(std::chrono::milliseconds every) {
  std::unique_lock lock(mutex_);
  while (!closed_) {
    wake_.wait_for(lock, every);
    if (closed_ || !error_.empty()) continue;
    try {
      writer_->flush();
    } catch (const std::exception& e) {
      error_ = e.what();
    }
  }
}

void Recorder::setRig(const std::string& configYaml, const std::string& cameraYaml, const mcap::StringMap& extra) {
  mcap::StringMap entries = extra;
  entries[kConfigYamlKey] = configYaml;
  entries[kCameraYamlKey] = cameraYaml;
  addMetadata(kConfigMetadata, entries);
}

void Recorder::addMetadata(const std::string& name, const mcap::StringMap& entries) {
  std::lock_guard lock(mutex_);
  if (closed_ || !error_.empty()) return;
  try {
    writer_->addMetadata(name, entries);
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

void Recorder::write(const std::string& topic, Schema schema, Stamp stamp, const std::vector<std::uint8_t>& data) {
  std::lock_guard lock(mutex_);
  if (closed_ || !error_.empty()) return;
  try {
    auto ch = channels_.find(topic);
    if (ch == channels_.end()) {
      auto sc = schemas_.find(schema);
      if (sc == schemas_.end()) {
        const std::string_view text = schemaJson(schema);
        sc = schemas_.emplace(schema, writer_->addSchema(std::string(schemaName(schema)), "jsonschema",
                                                         {reinterpret_cast<const std::uint8_t*>(text.data()), text.size()})).first;
      }
      ch = channels_.emplace(topic, writer_->addChannel(sc->second, topic, "json")).first;
    }
    const auto t = static_cast<std::uint64_t>(stamp.ns);
    writer_->write(ch->second, t, t, data);
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

void Recorder::record(const SerialChunk& m) { write(topic::kLaserRaw, Schema::kRawSerial, m.stamp, encode(m)); }
void Recorder::record(const CanMessage& m) { write(topic::kCan, Schema::kCanFrame, m.stamp, encode(m)); }
void Recorder::record(const CameraFrame& m) {
  const Schema s = schemaOf(m);
  write(s == Schema::kRawImage ? topic::kCameraRaw : topic::kCameraCompressed, s, m.stamp, encode(m));
}
void Recorder::record(const LaserScan& m) { write(topic::kLaserScan, Schema::kLaserScan, m.stamp, encode(m)); }
void Recorder::record(const TiltSample& m) { write(topic::kTilt, Schema::kTiltSample, m.stamp, encode(m)); }
void Recorder::record(const PointCloudMessage& m) { write(topic::kSweep, Schema::kPointCloud, m.stamp, encode(m)); }
void Recorder::record(const AnnotationsMessage& m) { write(topic::kDetections, Schema::kImageAnnotations, m.stamp, encode(m)); }
void Recorder::record(const TransformMessage& m) { write(topic::kTransforms, Schema::kFrameTransform, m.stamp, encode(m)); }
void Recorder::record(const CameraCalibrationMessage& m) {
  write(topic::kCameraCalibration, Schema::kCameraCalibration, m.stamp, encode(m));
}
void Recorder::recordEncoded(const std::string& topic, Schema schema, Stamp stamp, const std::vector<std::uint8_t>& json) {
  write(topic, schema, stamp, json);
}

void Recorder::flush() {
  std::lock_guard lock(mutex_);
  if (closed_ || !error_.empty()) return;
  try {
    writer_->flush();
  } catch (const std::exception& e) {
    error_ = e.what();
  }
}

void Recorder::close() {
  {
    std::lock_guard lock(mutex_);
    if (closed_) {
      if (!error_.empty()) throw mcap::McapError(error_);
      return;
    }
    closed_ = true;
  }
  wake_.notify_all();
  if (flusher_.joinable()) flusher_.join();
  std::lock_guard lock(mutex_);
  if (error_.empty()) {
    try {
      writer_->close();
    } catch (const std::exception& e) {
      error_ = e.what();
    }
  }
  if (!error_.empty()) throw mcap::McapError(error_);
}

std::uint64_t Recorder::messages() const {
  std::lock_guard lock(mutex_);
  return writer_->messageCount();
}

std::string Recorder::error() const {
  std::lock_guard lock(mutex_);
  return error_;
}

}  // namespace fusedet::drivers::logs
