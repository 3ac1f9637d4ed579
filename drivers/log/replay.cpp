// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/log/replay.h"

#include <algorithm>
#include <thread>

#include "fusedet/drivers/lms291/link.h"
#include "fusedet/drivers/log/candump.h"

namespace fusedet::drivers::logs {

LogSource::LogSource(const std::filesystem::path& log, ReplayOptions options)
    : reader_(log), cursor_(reader_.messages()), options_(options) {}

std::optional<LogRig> LogSource::rig() const {
  const mcap::Metadata* m = reader_.index().findMetadata(kConfigMetadata);
  if (!m) return std::nullopt;
  LogRig rig;
  rig.entries = m->entries;
  if (auto it = m->entries.find(kConfigYamlKey); it != m->entries.end()) rig.configYaml = it->second;
  if (auto it = m->entries.find(kCameraYamlKey); it != m->entries.end()) rig.cameraYaml = it->second;
  return rig;
}

void LogSource::rewind(std::int64_t restampFromNs) {
  options_.restampFromNs = restampFromNs;
  cursor_ = reader_.messages();
  counters_ = {};
  firstLogTime_.reset();
  shiftNs_ = 0;
}

bool LogSource::waitUntilDue(std::uint64_t logTime, const std::atomic<bool>* stop) {
  if (!firstLogTime_) {
    firstLogTime_ = logTime;
    wallStart_ = std::chrono::steady_clock::now();
    if (options_.restamp) shiftNs_ = std::max(Stamp::now().ns, options_.restampFromNs) - static_cast<std::int64_t>(logTime);
  }
  if (!options_.realtime) return !(stop && stop->load());
  const double offsetS = static_cast<double>(logTime - *firstLogTime_) * 1e-9 / std::max(options_.speed, 1e-6);
  const auto due = wallStart_ + std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(offsetS));
  // Sleep in short slices so a stop request is seen promptly.
  for (;;) {
    if (stop && stop->load()) return false;
    const auto now = std::chrono::steady_clock::now();
    if (now >= due) return true;
    std::this_thread::sleep_for(std::min<std::chrono::steady_clock::duration>(due - now, std::chrono::milliseconds(20)));
  }
}

bool LogSource::step(const Handlers& h, const std::atomic<bool>* stop) {
  const mcap::LogIndex& x = reader_.index();
  for (;;) {
    if (stop && stop->load()) return false;
    std::optional<mcap::Message> m = cursor_.next();
    if (!m) return false;
    auto ch = x.channels.find(m->channelId);
    const std::string topic = ch == x.channels.end() ? "" : ch->second.topic;
    const bool serial = topic == topic::kLaserRaw, can = topic == topic::kCan,
               camera = topic == topic::kCameraRaw || topic == topic::kCameraCompressed;
    if (!serial && !can && !camera) {
      ++counters_.otherMessages;
      continue;
    }
    if (!waitUntilDue(m->logTime, stop)) return false;
    ++counters_.messages;
    // Decoded message -> restamped -> counted -> its handler; undecodable ones are skipped.
    auto deliver = [&](auto decoded, std::uint64_t& count, const auto& handler) {
      if (!decoded) return ++counters_.undecodable, false;
      decoded->stamp = decoded->stamp + shiftNs_;
      ++count;
      if (handler) handler(*decoded);
      return true;
    };
    bool ok;
    if (serial) {
      const std::function<void(const SerialChunk&)> countBytes = [&](const SerialChunk& c) {
        counters_.serialBytes += c.bytes.size();
        if (h.serial) h.serial(c);
      };
      ok = deliver(decodeSerial(m->data), counters_.serialChunks, countBytes);
    } else if (can) {
      ok = deliver(decodeCan(m->data), counters_.canFrames, h.can);
    } else {
      ok = deliver(decodeCamera(m->data), counters_.cameraFrames, h.camera);
    }
    if (!ok) continue;
    return true;
  }
}

SensorReplay::SensorReplay(const std::filesystem::path& log, SensorReplayConfig config, ReplayOptions options)
    : source_(log, options), config_(std::move(config)), tilt_(config_.tilt.node, config_.tilt.units) {
  resetScanDecoder();
}

void SensorReplay::resetScanDecoder() {
  const lms291::Lms291Config& l = config_.laser;
  // What Lms291::start() sets the device to: the unit, and measuring mode 0x0D for range+remission.
  scans_.reset(l.variant, l.remission, l.remission ? lms291::kMeasuringRemission : l.measuringMode, l.unit);
}

void SensorReplay::rewind(std::int64_t restampFromNs) {
  source_.rewind(restampFromNs);
  telegrams_ = lms291::TelegramReader{lms291::Direction::kFromDevice};
  scans_ = lms291::ScanDecoder{};
  resetScanDecoder();
  tilt_ = canopen::TiltTpdoDecoder(config_.tilt.node, config_.tilt.units);
  baud_ = 0;
  frames_ = 0;
}

void SensorReplay::drainTelegrams(const Handlers& h, int baud) {
  while (auto e = telegrams_.next()) {
    if (e->kind != lms291::StreamEvent::Kind::kTelegram) continue;
    if (auto scan = scans_.decode(e->telegram, baud); scan && h.scan) h.scan(*scan);
  }
}

// No silence rule here: the gap between two recorded reads is not a silence on the line. A reader
// thread that was late (a loaded machine) reads a telegram's rest long after its start; the live
// link saw no silence and completed it, so giving the start up on that gap lost a whole recorded
// telegram (seen: 1-3 replayed telegrams fewer than the live link decoded in 7 of 60 rig runs at
// load 8-13, and the replayed scan list shifted from the live one). The live link gives a pending
// frame up only after a silence it waited through; such a frame is garbage (the LMS leaves at most
// 14 ms inside a telegram), and here its CRC rejects it once the bytes it claims have come, and the
// reader searches those bytes again: the same telegrams as live.
void SensorReplay::onSerial(const SerialChunk& chunk, const Handlers& h) {
  if (chunk.baud != baud_) {  // the live link drops what was buffered at the old speed
    telegrams_.clear();
    telegrams_.setByteTime(static_cast<std::int64_t>(lms291::byteSeconds(std::max(chunk.baud, 1)) * 1e9));
    baud_ = chunk.baud;
  }
  telegrams_.feed(chunk.bytes, chunk.stamp);
  drainTelegrams(h, baud_);
}

bool SensorReplay::step(const Handlers& h, const std::atomic<bool>* stop) {
  LogSource::Handlers raw;
  raw.serial = [&](const SerialChunk& c) { onSerial(c, h); };
  raw.can = [&](const CanMessage& c) {
    const canopen::CanFrame f = toCanFrame(c);
    if (!tilt_.isTpdo(f)) return;  // SYNC, heartbeats, SDO, NMT, EMCY: the drive's business, not a sample
    if (auto t = tilt_.decode(f); t && h.tilt) h.tilt(t->sample);
  };
  raw.camera = [&](const CameraFrame& f) {
    ++frames_;
    if (h.frame) h.frame(f);
  };
  if (source_.step(raw, stop)) return true;
  // The log ended: what is still pending cannot complete; search it again until nothing is left.
  if (!(stop && stop->load()))
    while (telegrams_.expirePending()) drainTelegrams(h, baud_);
  return false;
}

void SensorReplay::run(const Handlers& handlers, const std::atomic<bool>* stop) {
  while (step(handlers, stop)) {
  }
}

SensorReplayCounters SensorReplay::counters() const {
  SensorReplayCounters c;
  c.raw = source_.counters();
  c.telegrams = telegrams_.counters();
  c.scans = scans_.scans();
  c.lostScans = scans_.lostScans();
  c.badScans = scans_.badScans();
  c.tiltSamples = tilt_.samples();
  c.badTpdos = tilt_.badPdos();
  c.frames = frames_;
  return c;
}

}  // namespace fusedet::drivers::logs
