// SPDX-License-Identifier: Apache-2.0
#pragma once
// ScanDecoder: device telegrams -> LaserScan messages, for the device state the driver set up
// (variant, range or range+remission output, measuring mode, unit). The live driver (Lms291) and
// log replay (logs::SensorReplay) use this one decoder, so a replayed log yields the scans the
// live driver would have produced from the same bytes.
//
// Stamp = reception of the telegram's last byte minus its line time at `baud` (10 bits/byte).
// Beams of one mirror rotation are beamDuration apart; interlaced scans get beamDuration 0.

#include <cstdint>
#include <optional>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/scan_assembler.h"
#include "fusedet/drivers/lms291/telegram.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::lms291 {

inline constexpr double kMirrorHz = 75.0;  // one mirror rotation = one (partial) scan (§5)

class ScanDecoder {
 public:
  // Starts a new stream: forgets partial scans and telegram indices (sequence numbers go on).
  void reset(Variant variant, bool remission, std::uint8_t measuringMode, Unit unit);
  // A scan when `t` completes one; replies, power-on and other telegrams give nothing.
  std::optional<LaserScan> decode(const Telegram& t, int baud);

  std::uint64_t scans() const { return scans_; }
  std::uint64_t lostScans() const { return lostScans_ + assembler_.droppedGroups(); }
  std::uint64_t badScans() const { return badScans_; }

 private:
  LaserScan makeScan(const Telegram& t, int baud) const;

  Variant variant_;
  bool remission_ = false;
  std::uint8_t measuringMode_ = kMeasuring8m;
  Unit unit_ = Unit::kMm;
  ScanAssembler assembler_;
  std::optional<std::uint8_t> lastTelegramIndex_;
  std::uint64_t sequence_ = 0;
  std::uint64_t scans_ = 0, lostScans_ = 0, badScans_ = 0;
};

}  // namespace fusedet::drivers::lms291
