// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/replay_source.h"

#include <spdlog/spdlog.h>

#include <algorithm>

#include "fusedet/daemon/thread_info.h"

namespace fusedet::daemon {
namespace {

std::string describeDamage(const drivers::mcap::LogIndex& index) {
  std::string out;
  if (index.truncation) out = "log cut short: " + index.truncation->describe();
  for (const std::string& p : index.problems) out += (out.empty() ? "" : "; ") + p;
  return out;
}

}  // namespace

ReplaySource::ReplaySource(ReplaySettings settings) : settings_(std::move(settings)) {
  options_.realtime = settings_.realtime;
  options_.speed = settings_.speed;
  options_.restamp = settings_.restamp;
  replay_ = std::make_unique<drivers::logs::SensorReplay>(settings_.log, settings_.sensors, options_);
  const auto& index = replay_->source().index();
  logMessages_ = index.messages;
  damage_ = describeDamage(index);
  if (!damage_.empty()) spdlog::warn("replay {}: {}; replaying what is intact", settings_.log.string(), damage_);
}

ReplaySource::~ReplaySource() { stop(); }

void ReplaySource::start(SensorSink& sink) {
  stop_ = false;
  thread_ = std::thread([this, &sink] { run(sink); });
}

void ReplaySource::stop() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
}

void ReplaySource::record(const drivers::logs::SensorReplayCounters& counters) {
  std::lock_guard lock(mutex_);
  pass_ = counters;
}

void ReplaySource::run(SensorSink& sink) {
  nameThisThread("fd-replay");
  // The log may fail under the replay (I/O error, the file shrunk or was replaced): an exception
  // from the reader must not leave this thread (std::terminate). The replay ends there as a
  // failed source - status says why - and what was delivered is closed like a log's end.
  try {
    replay(sink);
  } catch (const std::exception& e) {
    {
      std::lock_guard lock(mutex_);
      error_ = std::string("replay failed: ") + e.what();
    }
    spdlog::error("replay {}: {}", settings_.log.string(), e.what());
    failed_ = true;
    sink.onEndOfStream();
    finished_ = true;
  }
}

void ReplaySource::replay(SensorSink& sink) {
  std::uint64_t delivered = 0;
  std::int64_t newest = 0;  // newest stamp delivered: the next pass is stamped after it
  drivers::logs::SensorReplay::Handlers h;
  h.scan = [&](const drivers::LaserScan& s) {
    sink.onScan(s);
    ++delivered;
    newest = std::max(newest, s.stamp.ns);
  };
  h.tilt = [&](const drivers::TiltSample& t) {
    sink.onTilt(t);
    ++delivered;
    newest = std::max(newest, t.stamp.ns);
  };
  h.frame = [&](const drivers::CameraFrame& f) {
    sink.onFrame(f);
    ++delivered;
    newest = std::max(newest, f.stamp.ns);
  };
  for (;;) {
    for (;;) {
      // As fast as possible = as fast as the pipeline takes it: wait, never drop.
      if (!settings_.realtime) sink.awaitRoom(stop_);
      if (!replay_->step(h, &stop_)) break;
      record(replay_->counters());
      std::lock_guard lock(mutex_);
      delivered_ = delivered;
    }
    if (stop_) return;
    sink.onEndOfStream();
    {
      std::lock_guard lock(mutex_);
      const auto pass = replay_->counters();
      crcErrors_ += pass.telegrams.crcErrors;
      lost_ += pass.lostScans + pass.badScans;
      pass_ = {};
      delivered_ = delivered;
      ++passes_;
    }
    spdlog::info("replay {}: end of log (pass {})", settings_.log.string(), passes_);
    if (!settings_.loop) break;
    // Faster than the clock, a pass restamped to "now" would go back in time behind the last one
    // (sweeps cut short at the seam, frames left unpaired): continue after its newest stamp. At
    // recorded speed the stamps never ran ahead of the clock and "now" is already after them: a
    // margin there would stamp the whole next pass ahead of the clock (latencies too short).
    options_.restampFromNs = newest >= Stamp::now().ns ? newest + 50'000'000 : 0;  // 50 ms: past the last scan's beams
    // Rewound, not reopened: opening indexes the whole file (~0.1 s of CPU for the demo log),
    // which would compete with the detection of the pass's last stack.
    replay_->rewind(options_.restampFromNs);
  }
  finished_ = true;
}

std::vector<SensorHealth> ReplaySource::health() const {
  SensorHealth h;
  h.name = "replay";
  h.state = failed_ ? "failed" : finished_ ? "finished" : (stop_ ? "stopped" : "replaying");
  std::lock_guard lock(mutex_);
  h.messages = delivered_;
  h.crcErrors = crcErrors_ + pass_.telegrams.crcErrors;  // finished passes + this one
  h.lost = lost_ + pass_.lostScans + pass_.badScans;
  h.lastError = error_.empty() ? damage_ : error_;
  h.passes = passes_;
  const auto& raw = pass_.raw;
  const double read = static_cast<double>(raw.messages + raw.undecodable + raw.otherMessages);
  h.progress = !settings_.loop && passes_ > 0 ? 1.0 : (logMessages_ ? std::min(1.0, read / static_cast<double>(logMessages_)) : 0.0);
  return {h};
}

}  // namespace fusedet::daemon
