// SPDX-License-Identifier: Apache-2.0
#pragma once
// ScanStream: runs an Lms291 on its own thread and keeps it running. When the port vanishes
// (USB adapter unplugged) or the device falls silent, it closes, waits (back-off doubling from
// 50 ms up to reconnectMax; while the device node is absent, it is watched every 20 ms instead)
// and re-initialises from scratch. stop() ends streaming, returns the
// device to 9600 baud and joins the thread.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/stream_state.h"
#include "fusedet/drivers/log/recorder.h"

namespace fusedet::drivers::lms291 {

using drivers::StreamState;  // shared with the camera stream (stream_state.h)

struct ScanStreamCounters {
  Lms291Counters device;
  std::uint64_t reconnects = 0;     // re-initialisations after the first
  std::uint64_t failedInits = 0;
  std::string lastError;
};

class ScanStream {
 public:
  using ScanHandler = std::function<void(const LaserScan&)>;
  ScanStream(Lms291Config config, ScanHandler onScan,
             std::chrono::milliseconds reconnectMax = std::chrono::milliseconds(5000),
             std::chrono::milliseconds silenceLimit = std::chrono::milliseconds(1000));
  ~ScanStream();
  ScanStream(const ScanStream&) = delete;
  ScanStream& operator=(const ScanStream&) = delete;

  // Recording hook: every raw chunk read from the port with its stamp (call before start()).
  void setRawHook(std::function<void(std::span<const std::uint8_t>, Stamp)> hook) {
    device_.link().setRawHook(std::move(hook));
  }

  // Recording hook for sensor logs: every chunk read from the port goes to `recorder` as a
  // logs::SerialChunk (device path, line speed at the read). Call before start(); the recorder
  // must outlive the stream.
  void setRecorder(logs::Recorder* recorder);

  void start();
  // Streaming off, device back to 9600 (if reachable), thread joined. Returns the result of
  // the device stop (ok if the device was not connected).
  Result<void> stop();

  StreamState state() const { return state_.load(); }
  ScanStreamCounters counters() const;

 private:
  void run();
  bool sleepFor(std::chrono::milliseconds d);  // false if stop() was called
  bool waitForDevice(const std::string& path);  // until the node exists; false if stopped
  static constexpr std::chrono::milliseconds kDevicePoll{20};

  Lms291 device_;
  ScanHandler onScan_;
  std::chrono::milliseconds reconnectMax_;
  std::chrono::milliseconds silenceLimit_;
  std::atomic<StreamState> state_{StreamState::kStopped};
  std::atomic<bool> running_{false};
  std::atomic<bool> cancel_{false};  // ends the device's waits (e.g. a slow init) on stop()
  std::thread thread_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  ScanStreamCounters counters_;
  Result<void> stopResult_;
};

}  // namespace fusedet::drivers::lms291
