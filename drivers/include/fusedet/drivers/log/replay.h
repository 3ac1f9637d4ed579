// SPDX-License-Identifier: Apache-2.0
#pragma once
// Replay of a sensor log (docs/log-format.md) through the decoders the live drivers use.
//
// LogSource gives the raw streams back - serial chunks, CAN frames, camera buffers - in log-time
// order (ties: file order), either paced like the recording (`realtime`, optionally `speed`x) or
// as fast as possible. Without `restamp` every stamp is the recorded one, so two replays of a log
// deliver identical messages in identical order (deterministic).
//
// SensorReplay feeds those raw streams into the live decoders: serial bytes into the LMS telegram
// reader and lms291::ScanDecoder (the code Lms291 uses), CAN frames into canopen::TiltTpdoDecoder
// (the TPDO1 -> TiltSample rule TiltDrive uses), camera buffers pass through as CameraFrame (decode with
// fusion::decodeCameraFrame, as live). What comes out is what the live drivers would have emitted.

#include <atomic>
#include <chrono>
#include <filesystem>
#include <functional>
#include <optional>
#include <string>

#include "fusedet/drivers/canopen/tilt_drive.h"
#include "fusedet/drivers/canopen/tilt_tpdo.h"
#include "fusedet/drivers/log/channels.h"
#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/lms291/scan_decoder.h"
#include "fusedet/drivers/lms291/telegram.h"

namespace fusedet::drivers::logs {

struct ReplayOptions {
  bool realtime = false;  // pace by log time; false = as fast as possible
  double speed = 1.0;     // with realtime: 2 = twice as fast
  // Shift every stamp by (Stamp::now() at the first message - its log time), so replayed data
  // looks live (latency measurements). Breaks bit-for-bit determinism of stamps only.
  bool restamp = false;
  // With restamp: the first message is stamped no earlier than this (CLOCK_MONOTONIC ns), so a
  // looping replay's next pass continues after the previous one although that ran ahead of the
  // clock (as fast as possible, or speed > 1). 0 = now.
  std::int64_t restampFromNs = 0;
};

struct ReplayCounters {
  std::uint64_t messages = 0;       // raw messages delivered
  std::uint64_t serialChunks = 0, serialBytes = 0, canFrames = 0, cameraFrames = 0;
  std::uint64_t undecodable = 0;    // raw messages whose JSON did not decode (skipped)
  std::uint64_t otherMessages = 0;  // decoded/derived channels, skipped by replay
};

// The rig a log was recorded (or synthesised) with: metadata "fusedet.config".
struct LogRig {
  std::string configYaml;  // fusedet.yaml format (daemon::parseConfig reads it)
  std::string cameraYaml;  // ROS camera_info (fusion::parseCameraModel reads it)
  mcap::StringMap entries;  // every entry, including the two above
};

class LogSource {
 public:
  struct Handlers {
    std::function<void(const SerialChunk&)> serial;
    std::function<void(const CanMessage&)> can;
    std::function<void(const CameraFrame&)> camera;
  };

  // Throws mcap::McapError (missing file, not MCAP). A damaged or cut log replays what is intact
  // (index() says what is not).
  explicit LogSource(const std::filesystem::path& log, ReplayOptions options = {});

  const mcap::LogIndex& index() const { return reader_.index(); }
  std::optional<LogRig> rig() const;
  // Delivers the next raw message to its handler (sleeping until it is due when realtime).
  // False at the end of the log, or when *stop became true (checked while sleeping, too).
  bool step(const Handlers& handlers, const std::atomic<bool>* stop = nullptr);
  const ReplayCounters& counters() const { return counters_; }
  // Back to the first message, as if just opened (counters, pacing and re-stamping start anew),
  // without reading the file's index again: the next pass of a looping replay. restampFromNs
  // replaces ReplayOptions::restampFromNs for that pass.
  void rewind(std::int64_t restampFromNs = 0);

 private:
  bool waitUntilDue(std::uint64_t logTime, const std::atomic<bool>* stop);
  mcap::McapReader reader_;
  mcap::MessageCursor cursor_;
  ReplayOptions options_;
  ReplayCounters counters_;
  std::optional<std::uint64_t> firstLogTime_;
  std::chrono::steady_clock::time_point wallStart_;
  std::int64_t shiftNs_ = 0;
};

struct SensorReplayConfig {
  lms291::Lms291Config laser;  // variant, remission, measuring mode: what the driver set the device to
  canopen::TiltDriveConfig tilt;  // the live drive's config: node id and position units (TPDO1 decoding)
};

struct SensorReplayCounters {
  ReplayCounters raw;
  lms291::ReaderCounters telegrams;  // bytes, telegrams, CRC errors, resyncs, expired frames
  std::uint64_t scans = 0, lostScans = 0, badScans = 0;
  std::uint64_t tiltSamples = 0;
  std::uint64_t badTpdos = 0;  // TPDO1 frames too short to decode
  std::uint64_t frames = 0;
};

class SensorReplay {
 public:
  struct Handlers {
    std::function<void(const LaserScan&)> scan;
    std::function<void(const TiltSample&)> tilt;
    std::function<void(const CameraFrame&)> frame;
  };

  SensorReplay(const std::filesystem::path& log, SensorReplayConfig config, ReplayOptions options = {});

  // One raw message: its decoded results go to the handlers. False at the end or on stop; the
  // last call also flushes a telegram the log ended inside (given up, as after a silence).
  bool step(const Handlers& handlers, const std::atomic<bool>* stop = nullptr);
  // Steps until the end or stop.
  void run(const Handlers& handlers, const std::atomic<bool>* stop = nullptr);
  // Back to the start with fresh decoders and counters: what a new SensorReplay on the same log
  // (with ReplayOptions::restampFromNs = restampFromNs) gives, without opening and indexing the
  // file again (that costs a pass over the whole file).
  void rewind(std::int64_t restampFromNs = 0);

  LogSource& source() { return source_; }
  SensorReplayCounters counters() const;

 private:
  void resetScanDecoder();
  void onSerial(const SerialChunk& chunk, const Handlers& h);
  void drainTelegrams(const Handlers& h, int baud);

  LogSource source_;
  SensorReplayConfig config_;
  lms291::TelegramReader telegrams_{lms291::Direction::kFromDevice};
  lms291::ScanDecoder scans_;
  canopen::TiltTpdoDecoder tilt_;
  int baud_ = 0;
  std::uint64_t frames_ = 0;
};

}  // namespace fusedet::drivers::logs
