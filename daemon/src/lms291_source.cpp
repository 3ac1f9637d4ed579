// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/lms291_source.h"

#include <cmath>

#include "fusedet/daemon/rig.h"

namespace fusedet::daemon {

Lms291Source::Lms291Source(const Config& config)
    : config_(laserConfig(config)), reconnectMaxS_(config.laser.reconnectMaxS) {}

Lms291Source::~Lms291Source() { stop(); }

void Lms291Source::start(SensorSink& sink) {
  stream_ = std::make_unique<drivers::lms291::ScanStream>(
      config_, [&sink](const drivers::LaserScan& scan) { sink.onScan(scan); },
      std::chrono::milliseconds(std::lround(reconnectMaxS_ * 1000)));
  stream_->start();
}

void Lms291Source::stop() {
  if (stream_) (void)stream_->stop();
}

std::vector<SensorHealth> Lms291Source::health() const {
  SensorHealth h;
  h.name = "laser";
  if (!stream_) {
    h.state = "stopped";
    return {h};
  }
  const auto c = stream_->counters();
  h.state = std::string(drivers::toString(stream_->state()));
  h.messages = c.device.scans;
  h.crcErrors = c.device.link.reader.crcErrors;
  h.reconnects = c.reconnects;
  h.lost = c.device.lostScans;
  h.lastError = c.lastError;
  return {h};
}

}  // namespace fusedet::daemon
