// SPDX-License-Identifier: Apache-2.0
#pragma once
// FrameStream: runs a V4l2Camera on its own thread and keeps it running. No frame for
// `stallLimit`: the stream is restarted (STREAMOFF/STREAMON) up to `maxRestarts` times in a row,
// then the device is reopened. A vanished device (unplugged camera) is closed; while its node is
// absent it is watched every 20 ms and reopened as soon as it is back; other failures back off
// (50 ms doubling to `reconnectMax`). deviceArrived() (e.g. from a USB hotplug callback) ends a
// back-off at once. stop() joins the thread and leaves the device closed.
// With a device resolver (a USB camera named by VID:PID, whose node may change when re-plugged)
// the node is looked up anew before every open, and while the device is absent the lookup is
// repeated every 100 ms instead of watching the old node.

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
  // Returns the node to open, or why there is none now (device absent, driver not bound yet).
  using DeviceResolver = std::function<Result<std::string>()>;
  FrameStream(CameraConfig config, FrameHandler onFrame, FrameStreamTiming timing = {},
              std::unique_ptr<V4l2Io> io = makeKernelIo());
  ~FrameStream();
  FrameStream(const FrameStream&) = delete;
  FrameStream& operator=(const FrameStream&) = delete;

  // Recording hook: every dequeued buffer (call before start()).
  void setRawHook(RawHook hook) { camera_.setRawHook(std::move(hook)); }
  // Where the node is found before every open (call before start()); CameraConfig::device is
  // then only the first guess, replaced by what the resolver returns.
  void setDeviceResolver(DeviceResolver resolver) { resolver_ = std::move(resolver); }

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
  bool resolveDevice();                       // true: camera_ names the resolver's node
  void stream();                              // streams until stop, a device error or a reopen is due
  void noteError(const Error& e);
  static constexpr std::chrono::milliseconds kDevicePoll{20};
  static constexpr std::chrono::milliseconds kResolvePoll{100};  // a sysfs scan: cheap, not free

  V4l2Camera camera_;
  FrameHandler onFrame_;
  DeviceResolver resolver_;
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
