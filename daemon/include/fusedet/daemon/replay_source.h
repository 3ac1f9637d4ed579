// SPDX-License-Identifier: Apache-2.0
#pragma once
// ReplaySource: a sensor log (docs/log-format.md) replayed into the pipeline as the sensors would
// deliver it - raw LMS bytes, CAN frames and camera buffers through the live decoders
// (drivers::logs::SensorReplay), so the pipeline's sweep assembly, pairing, fusion and detection
// run exactly as live. Paced like the recording, or as fast as possible: then it waits for room
// in the pipeline before each message (SensorSink::awaitRoom), so nothing is dropped and two
// replays give the same stacks and detections. At the end of the log the open sweep is closed
// (SensorSink::onEndOfStream); with `loop` the log starts again.

#include <atomic>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>

#include "fusedet/daemon/source.h"
#include "fusedet/drivers/log/replay.h"

namespace fusedet::daemon {

struct ReplaySettings {
  std::filesystem::path log;
  drivers::logs::SensorReplayConfig sensors;  // rig.h sensorReplayConfig(the log's rig)
  bool realtime = true;  // false: as fast as the pipeline takes it
  double speed = 1.0;    // with realtime
  bool restamp = true;   // stamps shifted so each pass starts "now"
  bool loop = false;     // start again at the end (needs restamp)
};

class ReplaySource : public Source {
 public:
  // Opens the log: throws mcap::McapError when it is missing or not MCAP. A damaged or cut log
  // replays what is intact; health().lastError says what is not.
  explicit ReplaySource(ReplaySettings settings);
  ~ReplaySource() override;
  void start(SensorSink& sink) override;
  void stop() override;
  std::vector<SensorHealth> health() const override;
  bool finished() const override { return finished_.load(); }
  bool failed() const override { return failed_.load(); }
  // What is wrong with the log ("" when intact).
  const std::string& damage() const { return damage_; }
  // Messages of the log's intact part (what progress counts against).
  std::uint64_t logMessages() const { return logMessages_; }

 private:
  void run(SensorSink& sink);
  void replay(SensorSink& sink);
  void record(const drivers::logs::SensorReplayCounters& counters);

  ReplaySettings settings_;
  drivers::logs::ReplayOptions options_;
  std::unique_ptr<drivers::logs::SensorReplay> replay_;  // this pass; the replay thread only
  std::uint64_t logMessages_ = 0;                        // messages in the intact part of the log
  std::string damage_;
  std::thread thread_;
  std::atomic<bool> stop_{false}, finished_{false}, failed_{false};

  mutable std::mutex mutex_;  // guards the counters below
  drivers::logs::SensorReplayCounters pass_;  // this pass
  std::uint64_t delivered_ = 0;               // scans, tilt samples and frames handed on, all passes
  std::uint64_t crcErrors_ = 0, lost_ = 0;    // all finished passes (plus pass_)
  std::uint64_t passes_ = 0;
  std::string error_;  // why the replay failed (the reader threw: I/O error, file changed)
};

}  // namespace fusedet::daemon
