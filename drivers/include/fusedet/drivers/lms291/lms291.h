// SPDX-License-Identifier: Apache-2.0
#pragma once
// Lms291: the device layer of the SICK LMS 291 driver. Finds the device's current speed by
// probing, switches to the configured speed, sets units (mm), measuring mode, variant, starts
// continuous output and turns the telegrams into LaserScan messages; stop() turns streaming
// off and returns the device to 9600 baud so the next start (or another program) finds it.
//
// One thread uses an Lms291 at a time; ScanStream (scan_stream.h) adds reconnection.

#include <chrono>
#include <cstdint>
#include <optional>
#include <string>

#include "fusedet/core/result.h"
#include "fusedet/drivers/lms291/link.h"
#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/scan_decoder.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::lms291 {

struct Lms291Config {
  std::string device = "/dev/ttyUSB0";
  int baud = 38400;                  // 9600 | 19200 | 38400 | 500000
  Variant variant{180, 50};          // 180 deg / 0.5 deg
  bool remission = false;            // range + remission telegrams (F5); needs 1 deg resolution
  bool interlaced = false;           // stream partial scans (mode 2A) and merge them here
  bool realTimeIndices = false;      // ask for scan/telegram indices: lost scans become visible
  std::uint8_t measuringMode = kMeasuring8m;  // config byte 5 (remission forces 0x0D)
  Unit unit = Unit::kMm;             // config byte 6: mm (8 m in 13-bit modes) or cm (80 m)
  bool forceTermios2 = false;        // set speeds with BOTHER even where cfsetspeed works
  std::chrono::milliseconds ackTimeout{100};
  std::chrono::milliseconds replyTimeout{1000};
  std::chrono::milliseconds modeTimeout{3000};     // mode changes may take up to 3 s
  std::chrono::milliseconds configTimeout{15000};  // writing the configuration up to 15 s
  std::chrono::milliseconds baudSwitchPause{250};  // after changing speed, before verifying
  int retries = 3;

  // Empty when usable, else the reason.
  std::string validate() const;
};

struct Lms291Counters {
  LinkCounters link;
  std::uint64_t scans = 0;            // LaserScans emitted
  std::uint64_t lostScans = 0;        // telegram-index gaps (realTimeIndices) + dropped partial groups
  std::uint64_t badScans = 0;         // valid CRC but inconsistent content (count, unit, size)
  std::uint64_t statusWarnings = 0;   // telegrams whose status byte needs attention
  std::uint64_t inits = 0;            // successful initialisations
};

// What initialisation found.
struct DeviceInfo {
  int foundBaud = 0;   // the speed the device answered at
  std::string type;    // e.g. "LMS291;S05"
  DeviceStatus status;
};

class Lms291 {
 public:
  explicit Lms291(Lms291Config config);

  // Opens the port and brings the device into continuous output. Safe to call again after a
  // failure or a vanished port: it starts from scratch (full re-init).
  Result<DeviceInfo> start();
  // Next scan (merging partial scans); timed_out when none arrives within `timeout`.
  Result<LaserScan> readScan(std::chrono::milliseconds timeout);
  // Streaming off, back to 9600 baud, port closed. Best effort: reports the first failure.
  Result<void> stop();
  void close();  // drop the port without talking to the device (it is gone)

  // Individual steps (used by start(), `fusedet lms probe` and tests).
  Result<void> open();
  Result<int> detectBaud();
  Result<void> switchBaud(int baud);
  Result<std::string> queryType();
  Result<DeviceStatus> queryStatus();
  Result<ConfigBlock> readConfig();
  Result<void> writeConfig(const ConfigBlock& config);
  Result<void> setVariant(Variant v);
  Result<void> setMode(Mode mode, std::span<const std::uint8_t> params = {});

  const Lms291Config& config() const { return config_; }
  Lms291Counters counters() const;
  Link& link() { return link_; }
  bool streaming() const { return streaming_; }
  // Last status byte that needed attention (warnings are also logged once per change).
  StatusByte lastStatus() const { return lastStatus_; }

 private:
  RequestOptions options(std::chrono::milliseconds replyTimeout) const;
  std::optional<LaserScan> handle(const Telegram& t);
  void noteStatus(std::uint8_t status);

  Lms291Config config_;
  Link link_;
  ScanDecoder decoder_;     // telegrams -> scans (shared with log replay)
  Lms291Counters counters_;  // statusWarnings and inits; scan counts come from decoder_
  bool streaming_ = false;
  bool stopping_ = false;  // stop(): fewer retries
  StatusByte lastStatus_;
};

}  // namespace fusedet::drivers::lms291
