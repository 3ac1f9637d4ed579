#include "fusedet/daemon/lms291_source.h"

#include <cmath>

namespace fusedet::daemon {

drivers::lms291::Lms291Config lms291ConfigFrom(const Config::Laser& laser) {
  drivers::lms291::Lms291Config c;
  c.device = laser.device;
  c.baud = laser.baud;
  c.variant = {laser.angleDeg, static_cast<int>(std::lround(laser.resolutionDeg * 100))};
  c.remission = laser.remission;
  return c;
}

Lms291Source::Lms291Source(const Config::Laser& laser) : config_(laser) {}

Lms291Source::~Lms291Source() { stop(); }

void Lms291Source::start(SensorSink& sink) {
  stream_ = std::make_unique<drivers::lms291::ScanStream>(
      lms291ConfigFrom(config_), [&sink](const drivers::LaserScan& scan) { sink.onScan(scan); },
      std::chrono::milliseconds(std::lround(config_.reconnectMaxS * 1000)));
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
