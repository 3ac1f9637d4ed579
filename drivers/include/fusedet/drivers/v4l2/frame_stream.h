#pragma once
// FrameStream: runs a V4l2Camera on its own thread and keeps it running. No frame for
// `stallLimit`: the stream is restarted (STREAMOFF/STREAMON) up to `maxRestarts` times in a row,
// then the device is reopened. A vanished device (unplugged camera) is closed; while its node is
// absent it is watched every 20 ms and reopened as soon as it is back; other failures back off
// (50 ms doubling to `reconnectMax`). deviceArrived() (e.g. from a USB hotplug callback) ends a
// back-off at once. stop() joins the thread and leaves the device closed.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <optional>
#include <string>
#include <thread>

#include "fusedet/drivers/stream_state.h"
#include "fusedet/drivers/v4l2/camera.h"

namespace fusedet::drivers::v4l2 {

struct FrameStreamTiming {
  std::chrono::milliseconds readTimeout{100};     // one poll; also how fast stop() is noticed
  std::chrono::milliseconds stallLimit{2000};     // no frame this long = stalled
  int maxRestarts = 2;                            // stream restarts in a row before a reopen
  std::chrono::milliseconds reconnectMax{5000};   // back-off ceiling
};

struct FrameStreamCounters {
  CameraCounters camera;
  std::uint64_t stalls = 0;          // stall limits that expired
  std::uint64_t streamRestarts = 0;  // STREAMOFF/STREAMON after a stall
  std::uint64_t reopens = 0;         // successful starts after the first
  std::uint64_t failedOpens = 0;
  std::string lastError;
};

class FrameStream {
 public:
  using FrameHandler = std::function<void(const CameraFrame&)>;
  FrameStream(CameraConfig config, FrameHandler onFrame, FrameStreamTiming timing = {},
              std::unique_ptr<V4l2Io> io = makeKernelIo());
  ~FrameStream();
  FrameStream(const FrameStream&) = delete;
  FrameStream& operator=(const FrameStream&) = delete;

  // Recording hook: every dequeued buffer (call before start()).
  void setRawHook(RawHook hook) { camera_.setRawHook(std::move(hook)); }

  void start();
  void stop();
  // The device (re)appeared: end a back-off now (thread-safe; a no-op while streaming).
  void deviceArrived();

  StreamState state() const { return state_.load(); }
  FrameStreamCounters counters() const;
  std::optional<CameraInfo> info() const;  // of the current or last successful start

 private:
  void run();
  bool sleepFor(std::chrono::milliseconds d);  // false once stop() was called
  bool waitForDevice();                       // until the node exists; false once stopped
  void stream();                              // streams until stop, a device error or a reopen is due
  void noteError(const Error& e);
  static constexpr std::chrono::milliseconds kDevicePoll{20};

  V4l2Camera camera_;
  FrameHandler onFrame_;
  FrameStreamTiming timing_;
  std::atomic<StreamState> state_{StreamState::kStopped};
  std::atomic<bool> running_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  bool arrived_ = false;  // guarded by mutex_
  FrameStreamCounters counters_;
  std::optional<CameraInfo> info_;
};

}  // namespace fusedet::drivers::v4l2
