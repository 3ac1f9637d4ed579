// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/scan_stream.h"

#include <spdlog/spdlog.h>

#include <filesystem>

namespace fusedet::drivers::lms291 {

ScanStream::ScanStream(Lms291Config config, ScanHandler onScan, std::chrono::milliseconds reconnectMax,
                       std::chrono::milliseconds silenceLimit)
    : device_(std::move(config)), onScan_(std::move(onScan)), reconnectMax_(reconnectMax), silenceLimit_(silenceLimit) {
  device_.link().setCancelFlag(&cancel_);
}

ScanStream::~ScanStream() { (void)stop(); }

void ScanStream::setRecorder(logs::Recorder* recorder) {
  // Runs on the stream thread, where reading the link's current speed is safe.
  setRawHook([this, recorder](std::span<const std::uint8_t> bytes, Stamp stamp) {
    recorder->record(logs::SerialChunk{stamp, device_.config().device, device_.link().baud(), {bytes.begin(), bytes.end()}});
  });
}

void ScanStream::start() {
  if (running_.exchange(true)) return;
  cancel_ = false;
  thread_ = std::thread([this] { run(); });
}

Result<void> ScanStream::stop() {
  if (!running_.exchange(false)) return {};
  cancel_ = true;
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
  std::lock_guard lock(mutex_);
  return stopResult_;
}

ScanStreamCounters ScanStream::counters() const {
  std::lock_guard lock(mutex_);
  ScanStreamCounters c = counters_;
  return c;
}

bool ScanStream::sleepFor(std::chrono::milliseconds d) {
  std::unique_lock lock(mutex_);
  wake_.wait_for(lock, d, [this] { return !running_.load(); });
  return running_.load();
}

bool ScanStream::waitForDevice(const std::string& path) {
  std::error_code ec;
  while (!std::filesystem::exists(path, ec))
    if (!sleepFor(kDevicePoll)) return false;
  return running_.load();
}

void ScanStream::run() {
  const std::string& dev = device_.config().device;
  const auto kBackoffMin = std::chrono::milliseconds(50);
  auto backoff = kBackoffMin;
  bool everStarted = false;
  while (running_) {
    state_ = StreamState::kConnecting;
    auto info = device_.start();
    if (!info && !running_) break;  // cancelled: stop() below still returns the device to 9600
    if (!info) {
      device_.close();
      {
        std::lock_guard lock(mutex_);
        ++counters_.failedInits;
        counters_.lastError = info.error().message();
        counters_.device = device_.counters();
      }
      state_ = StreamState::kBackingOff;
      if (info.error().code == std::errc::no_such_file_or_directory) {
        // The device node is gone (adapter unplugged): watching for it costs a stat, not an init,
        // so poll it briskly instead of backing off; a replugged device is initialised at once.
        spdlog::debug("lms291 {}: {}; waiting for the device to reappear", dev, info.error().message());
        if (!waitForDevice(dev)) break;
        continue;
      }
      spdlog::debug("lms291 {}: init failed ({}), retrying in {} ms", dev, info.error().message(), backoff.count());
      if (!sleepFor(backoff)) break;
      backoff = std::min(backoff * 2, reconnectMax_);
      continue;
    }
    if (everStarted) {
      std::lock_guard lock(mutex_);
      ++counters_.reconnects;
    }
    everStarted = true;
    backoff = kBackoffMin;
    state_ = StreamState::kStreaming;
    auto lastScan = std::chrono::steady_clock::now();
    while (running_) {
      auto scan = device_.readScan(std::chrono::milliseconds(100));
      if (!running_) break;  // stop() cancelled the read
      if (scan) {
        lastScan = std::chrono::steady_clock::now();
        onScan_(*scan);
      } else if (scan.error().code != std::errc::timed_out) {
        spdlog::warn("lms291 {}: {}; reconnecting", dev, scan.error().message());
        std::lock_guard lock(mutex_);
        counters_.lastError = scan.error().message();
        break;
      } else if (std::chrono::steady_clock::now() - lastScan > silenceLimit_) {
        spdlog::warn("lms291 {}: no scan for {} ms; re-initialising", dev, silenceLimit_.count());
        std::lock_guard lock(mutex_);
        counters_.lastError = "silence";
        break;
      }
      std::lock_guard lock(mutex_);
      counters_.device = device_.counters();
    }
    if (!running_) break;
    device_.close();
    state_ = StreamState::kBackingOff;
    if (!sleepFor(backoff)) break;
  }
  cancel_ = false;  // the stop sequence itself must run
  Result<void> r = device_.stop();
  std::lock_guard lock(mutex_);
  counters_.device = device_.counters();
  stopResult_ = r;
  state_ = StreamState::kStopped;
}

}  // namespace fusedet::drivers::lms291
