#include "fusedet/drivers/log/tilt_decoder.h"


namespace fusedet::drivers::logs {

// The live drive's conversion (canopen::TiltUnits), so replay and live give the same angles.
canopen::TiltUnits TiltDecoderConfig::units() const {
  return canopen::TiltUnits{countsPerRev, gearRatio, static_cast<std::int32_t>(zeroOffsetCounts)};
}

double TiltDecoderConfig::countsToRad(std::int32_t counts) const { return units().toRad(counts); }

std::int32_t TiltDecoderConfig::radToCounts(double rad) const { return units().toCounts(rad); }

std::optional<TiltSample> TiltDecoder::decode(const CanMessage& f) {
  const auto node = static_cast<std::uint32_t>(config_.nodeId);
  if (f.error || f.extended || f.rtr) {
    ++counters_.other;
    return std::nullopt;
  }
  if (f.id == 0x080) {
    ++counters_.syncs;
    return std::nullopt;
  }
  if (f.id == 0x700 + node) {
    if (f.data.size() != 1) ++counters_.malformed;
    else ++counters_.heartbeats, counters_.lastState = f.data[0];
    return std::nullopt;
  }
  if (f.id != 0x180 + node) {
    ++counters_.other;
    return std::nullopt;
  }
  if (f.data.size() < 4) {
    ++counters_.malformed;
    return std::nullopt;
  }
  const auto raw = static_cast<std::int32_t>(static_cast<std::uint32_t>(f.data[0]) | (static_cast<std::uint32_t>(f.data[1]) << 8) |
                                             (static_cast<std::uint32_t>(f.data[2]) << 16) |
                                             (static_cast<std::uint32_t>(f.data[3]) << 24));
  TiltSample s{f.stamp, config_.countsToRad(raw), 0.0};
  if (last_ && s.stamp > last_->stamp) s.velocity = (s.angle - last_->angle) / ((s.stamp - last_->stamp) * 1e-9);
  last_ = s;
  ++counters_.positions;
  return s;
}

}  // namespace fusedet::drivers::logs
