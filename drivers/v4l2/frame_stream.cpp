// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/frame_stream.h"

#include <spdlog/spdlog.h>

#include <filesystem>

#include "fusedet/drivers/v4l2/stall_policy.h"

namespace fusedet::drivers::v4l2 {

FrameStream::FrameStream(CameraConfig config, FrameHandler onFrame, FrameStreamTiming timing, std::unique_ptr<V4l2Io> io)
    : camera_(std::move(config), std::move(io)), onFrame_(std::move(onFrame)), timing_(timing) {}

FrameStream::~FrameStream() { stop(); }

void FrameStream::start() {
  if (running_.exchange(true)) return;
  thread_ = std::thread([this] { run(); });
}

void FrameStream::stop() {
  if (!running_.exchange(false)) return;
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void FrameStream::deviceArrived() {
  {
    std::lock_guard lock(mutex_);
    arrived_ = true;
  }
  wake_.notify_all();
}

FrameStreamCounters FrameStream::counters() const {
  std::lock_guard lock(mutex_);
  return counters_;
}

std::optional<CameraInfo> FrameStream::info() const {
  std::lock_guard lock(mutex_);
  return info_;
}

bool FrameStream::sleepFor(std::chrono::milliseconds d) {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, d, [this] { return !running_.load() || arrived_; });
  arrived_ = false;
  return running_.load();
}

bool FrameStream::waitForDevice() {
  std::error_code ec;
  while (!std::filesystem::exists(camera_.config().device, ec))
    if (!sleepFor(kDevicePoll)) return false;
  return running_.load();
}

bool FrameStream::resolveDevice() {
  auto node = resolver_();
  if (!node) {
    bool changed;
    {
      std::lock_guard lock(mutex_);
      changed = counters_.lastError != node.error().message();
    }
    if (changed) spdlog::warn("camera: {}; looking again every {} ms", node.error().message(), kResolvePoll.count());
    noteError(node.error());
    return false;
  }
  if (*node != camera_.config().device) {
    spdlog::info("camera: device node {}", *node);
    camera_.setDevice(*node);
  }
  return true;
}

void FrameStream::noteError(const Error& e) {
  std::lock_guard lock(mutex_);
  counters_.lastError = e.message();
  counters_.camera = camera_.counters();
}

void FrameStream::stream() {
  StallPolicy stall(timing_.stallLimit, timing_.maxRestarts);
  stall.streamStarted(StallPolicy::Clock::now());
  const std::string& dev = camera_.config().device;
  while (running_) {
    auto frame = camera_.readFrame(timing_.readTimeout);
    const auto now = StallPolicy::Clock::now();
    if (frame) {
      stall.frameArrived(now);
      onFrame_(*frame);
    } else if (frame.error().code != std::errc::timed_out) {
      spdlog::warn("{}; reopening", frame.error().message());
      noteError(frame.error());
      return;
    }
    switch (stall.check(now)) {
      case StallAction::kNone: break;
      case StallAction::kRestartStream: {
        spdlog::warn("camera {}: no frame for {} ms; restarting the stream", dev, timing_.stallLimit.count());
        auto r = camera_.restartStream();
        {
          std::lock_guard lock(mutex_);
          ++counters_.stalls;
          ++counters_.streamRestarts;
        }
        if (!r) {
          spdlog::warn("{}; reopening", r.error().message());
          noteError(r.error());
          return;
        }
        break;
      }
      case StallAction::kReopen: {
        spdlog::warn("camera {}: still no frame after {} stream restarts; reopening", dev, timing_.maxRestarts);
        std::lock_guard lock(mutex_);
        ++counters_.stalls;
        counters_.lastError = "stalled";
        return;
      }
    }
    std::lock_guard lock(mutex_);
    counters_.camera = camera_.counters();
  }
}

void FrameStream::run() {
  const std::string& dev = camera_.config().device;
  const auto kBackoffMin = std::chrono::milliseconds(50);
  auto backoff = kBackoffMin;
  bool everStarted = false;
  while (running_) {
    state_ = StreamState::kConnecting;
    if (resolver_ && !resolveDevice()) {
      state_ = StreamState::kBackingOff;
      if (!sleepFor(kResolvePoll)) break;
      continue;
    }
    auto info = camera_.start();
    if (!info) {
      {
        std::lock_guard lock(mutex_);
        ++counters_.failedOpens;
      }
      noteError(info.error());
      state_ = StreamState::kBackingOff;
      const auto code = info.error().code;
      if (code == std::errc::no_such_file_or_directory) {
        // The node is gone (camera unplugged): a stat is cheap, so watch for it briskly.
        spdlog::debug("{}; waiting for the device to reappear", info.error().message());
        if (resolver_ ? !sleepFor(kResolvePoll) : !waitForDevice()) break;
        continue;
      }
      spdlog::warn("{}; retrying in {} ms", info.error().message(), backoff.count());
      if (!sleepFor(backoff)) break;
      backoff = std::min(backoff * 2, timing_.reconnectMax);
      continue;
    }
    for (const std::string& note : info->notes) spdlog::info("camera {}: {}", dev, note);
    {
      std::lock_guard lock(mutex_);
      if (everStarted) ++counters_.reopens;
      info_ = *info;
    }
    everStarted = true;
    backoff = kBackoffMin;
    state_ = StreamState::kStreaming;
    stream();
    camera_.stop();
    if (!running_) break;
    state_ = StreamState::kBackingOff;
    if (!sleepFor(kBackoffMin)) break;
  }
  camera_.stop();
  std::lock_guard lock(mutex_);
  counters_.camera = camera_.counters();
  state_ = StreamState::kStopped;
}

}  // namespace fusedet::drivers::v4l2
