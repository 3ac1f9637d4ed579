// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/lms291/scan_decoder.h"

#include <cmath>

namespace fusedet::drivers::lms291 {

void ScanDecoder::reset(Variant variant, bool remission, std::uint8_t measuringMode, Unit unit) {
  variant_ = variant;
  remission_ = remission;
  measuringMode_ = measuringMode;
  unit_ = unit;
  assembler_.reset(variant);
  lastTelegramIndex_.reset();
}

LaserScan ScanDecoder::makeScan(const Telegram& t, int baud) const {
  LaserScan scan;
  // Stamp = reception of the last byte minus the telegram's line time at the current speed.
  const double lineSeconds = byteSeconds(baud) * static_cast<double>(t.size());
  scan.stamp = t.received - static_cast<std::int64_t>(lineSeconds * 1e9);
  scan.startAngle = variant_.startDeg() * M_PI / 180.0;
  scan.angleStep = variant_.resolutionCdeg / 100.0 * M_PI / 180.0;
  // Beams of one rotation follow the mirror; interlaced beams come from several rotations.
  scan.beamDuration = variant_.rotations() == 1 ? (variant_.resolutionCdeg / 100.0 / 360.0) / kMirrorHz : 0.0;
  scan.status = t.status.value_or(0);
  scan.ranges.reserve(static_cast<std::size_t>(variant_.beams()));
  return scan;
}

std::optional<LaserScan> ScanDecoder::decode(const Telegram& t, int baud) {
  const std::size_t beams = static_cast<std::size_t>(variant_.beams());
  if (t.command == kMeasuredValues && !remission_) {
    auto mv = decodeMeasuredValues(t.data);
    if (!mv || mv->countWord.unit != unit_) {
      ++badScans_;
      return std::nullopt;
    }
    // Telegram-index gaps count lost scans in full-scan modes; with partial scans the
    // assembler counts the groups that a lost partial broke.
    if (mv->telegramIndex && !mv->countWord.partial) {
      if (lastTelegramIndex_) {
        const int gap = (*mv->telegramIndex - *lastTelegramIndex_ - 1 + 256) % 256;
        lostScans_ += static_cast<std::uint64_t>(gap);
        sequence_ += static_cast<std::uint64_t>(gap);
      }
      lastTelegramIndex_ = mv->telegramIndex;
    }
    std::vector<std::uint16_t> values;
    if (mv->countWord.partial) {
      auto merged = assembler_.add(mv->countWord.partialIndex, mv->values);
      if (!merged) return std::nullopt;
      values = std::move(*merged);
    } else {
      if (mv->values.size() != beams) {
        ++badScans_;
        return std::nullopt;
      }
      values = std::move(mv->values);
    }
    LaserScan scan = makeScan(t, baud);
    for (std::uint16_t v : values) scan.ranges.push_back(valueToMeters(v, measuringMode_, unit_));
    scan.sequence = sequence_++;
    ++scans_;
    return scan;
  }
  if (t.command == kRangeRemission && remission_) {
    auto blocks = decodeRangeRemission(t.data);
    if (!blocks || blocks->size() != 1 || (*blocks)[0].ranges.size() != beams || (*blocks)[0].countWord.unit != unit_) {
      ++badScans_;
      return std::nullopt;
    }
    const RemissionBlock& b = (*blocks)[0];
    LaserScan scan = makeScan(t, baud);
    for (std::size_t i = 0; i < beams; ++i) {
      scan.ranges.push_back(valueToMeters(b.ranges[i], measuringMode_, unit_));
      scan.remissions.push_back(static_cast<float>(b.remissions[i]));
    }
    scan.sequence = sequence_++;
    ++scans_;
    return scan;
  }
  return std::nullopt;  // replies and power-on telegrams are not scans
}

}  // namespace fusedet::drivers::lms291
