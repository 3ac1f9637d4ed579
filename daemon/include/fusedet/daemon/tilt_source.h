// SPDX-License-Identifier: Apache-2.0
#pragma once
// TiltSource: the live CANopen tilt motor as a pipeline source. Its thread opens the SocketCAN
// interface, starts the nodding drive (drivers::canopen::TiltDrive, which recovers from drive
// faults itself) and runs it; every TiltSample goes to the sink. When the interface is missing or
// fails, it retries every second until stopped.

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <thread>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/source.h"
#include "fusedet/drivers/canopen/tilt_drive.h"

namespace fusedet::daemon {

drivers::canopen::TiltDriveConfig tiltDriveConfigFrom(const Config::Tilt& tilt);

class TiltSource : public Source {
 public:
  explicit TiltSource(const Config::Tilt& tilt);
  ~TiltSource() override;
  void start(SensorSink& sink) override;
  void stop() override;
  std::vector<SensorHealth> health() const override;
  // stop() brings the motor to rest first: at most the drive's stop timeout plus thread joins.
  std::chrono::milliseconds stopTime() const override;
  std::string stopProblem() const override;

 private:
  void run(SensorSink& sink);

  std::string interface_;
  drivers::canopen::TiltDriveConfig config_;
  std::thread thread_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::string state_ = "stopped", lastError_;
  std::string stopProblem_;  // the last stop() could not confirm the motor at rest
  std::uint64_t reconnects_ = 0, opens_ = 0;
  drivers::canopen::TiltDriveCounters counters_;
};

}  // namespace fusedet::daemon
