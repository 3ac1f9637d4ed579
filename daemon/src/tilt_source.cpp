// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/tilt_source.h"

#include <spdlog/spdlog.h>

#include "fusedet/drivers/canopen/can_node.h"
#include "fusedet/drivers/canopen/socketcan_bus.h"
#include "fusedet/daemon/thread_info.h"

namespace fusedet::daemon {
namespace {
constexpr std::chrono::milliseconds kPoll{20};  // the source's threads look at their flags this often
}  // namespace

drivers::canopen::TiltDriveConfig tiltDriveConfigFrom(const Config::Tilt& t) {
  drivers::canopen::TiltDriveConfig c;
  c.node = t.nodeId;
  c.minDeg = t.minDeg;
  c.maxDeg = t.maxDeg;
  c.speedDegS = t.speedDegS;
  c.units = {t.countsPerRev, t.gearRatio, static_cast<std::int32_t>(t.zeroOffsetCounts)};
  c.heartbeatMs = t.heartbeatMs;
  return c;
}

TiltSource::TiltSource(const Config::Tilt& tilt) : interface_(tilt.interface), config_(tiltDriveConfigFrom(tilt)) {
  if (const std::string why = config_.validate(); !why.empty()) throw std::runtime_error("tilt: " + why);
}

TiltSource::~TiltSource() { stop(); }

void TiltSource::start(SensorSink& sink) {
  thread_ = std::thread([this, &sink] { run(sink); });
}

void TiltSource::stop() {
  stop_ = true;
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void TiltSource::run(SensorSink& sink) {
  nameThisThread("fd-tilt");
  auto setState = [this](const std::string& s, const std::string& error = {}) {
    std::lock_guard lock(mutex_);
    state_ = s;
    if (!error.empty()) lastError_ = error;
  };
  while (!stop_) {
    setState("connecting");
    drivers::canopen::SocketCanBus bus;
    if (auto opened = bus.open(interface_); !opened) {
      setState("backing off", opened.error().message());
    } else {
      {
        std::lock_guard lock(mutex_);
        if (opens_++) ++reconnects_;
      }
      drivers::canopen::TiltDrive drive(bus, config_, [&sink](const drivers::TiltSample& s) { sink.onTilt(s); });
      drive.nod();
      drive.start();
      setState("streaming");
      // Copies the drive's counters for `status` while it runs (its callbacks must not call it).
      std::atomic<bool> runnerDone{false};
      std::thread watcher([&] {
        while (!runnerDone && !stop_) {
          {
            std::lock_guard lock(mutex_);
            counters_ = drive.counters();
          }
          std::this_thread::sleep_for(kPoll);  // short: stop() joins this thread within its budget
        }
      });
      std::atomic<bool> runnerStop{false};
      std::thread runner([&] {
        auto r = drivers::canopen::runNode(bus, drive, runnerStop);
        if (!r) setState("backing off", r.error().message());
        runnerDone = true;
      });
      while (!stop_ && !runnerDone) std::this_thread::sleep_for(kPoll);
      if (stop_) {
        // Stopping: bring the motor to rest (the drive needs the runner for that), then end. The
        // drive ends its stop by config_.stopTimeout(), acknowledged or not; only an
        // acknowledged one is a motor known to be at rest.
        drive.stop();
        const auto until = std::chrono::steady_clock::now() + config_.stopTimeout() + kPoll;
        while (!drive.stopped() && !runnerDone && std::chrono::steady_clock::now() < until)
          std::this_thread::sleep_for(std::chrono::milliseconds(5));
        std::lock_guard lock(mutex_);
        if (!drive.stopConfirmed()) {
          stopProblem_ = "tilt motor (" + interface_ + " node " + std::to_string(config_.node) +
                         "): halt and shutdown not acknowledged within " + std::to_string(config_.stopTimeout().count()) +
                         " ms - it may still be moving";
          lastError_ = stopProblem_;
        }
      }
      runnerStop = true;
      runner.join();
      watcher.join();
      std::lock_guard lock(mutex_);
      counters_ = drive.counters();
    }
    std::unique_lock lock(mutex_);
    wake_.wait_for(lock, std::chrono::seconds(1), [this] { return stop_.load(); });
  }
  setState("stopped");
}

std::chrono::milliseconds TiltSource::stopTime() const {
  // The drive's stop, the wait's poll, the runner's tick and the watcher's poll.
  return config_.stopTimeout() + 3 * kPoll;
}

std::string TiltSource::stopProblem() const {
  std::lock_guard lock(mutex_);
  return stopProblem_;
}

std::vector<SensorHealth> TiltSource::health() const {
  std::lock_guard lock(mutex_);
  SensorHealth h;
  h.name = "tilt";
  h.state = state_;
  if (state_ == "streaming") h.state += std::string(" (") + std::string(drivers::canopen::toString(counters_.phase)) + ")";
  h.messages = counters_.samples;
  h.reconnects = reconnects_ + counters_.recoveries;
  h.lost = counters_.badPdos;
  h.lastError = counters_.lastFault.empty() ? lastError_ : counters_.lastFault;
  return {h};
}

}  // namespace fusedet::daemon
