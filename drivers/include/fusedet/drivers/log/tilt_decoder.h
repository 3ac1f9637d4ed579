#pragma once
// TiltDecoder: CAN frames of the CiA 402 tilt motor -> TiltSample, as the live tilt driver reads
// them: TPDO1 (COB-ID 0x180 + node) carries "position actual value" (0x6064, int32, little
// endian) on every SYNC; the sample is stamped at the TPDO's reception. Heartbeats (0x700 + node)
// and SYNC (0x080) are counted. Units (config `tilt:`): angle = 2 pi (counts - zero_offset_counts)
// / (counts_per_rev * gear_ratio); velocity = difference to the previous sample.

#include <cstdint>
#include <optional>

#include "fusedet/drivers/canopen/tilt_units.h"
#include "fusedet/drivers/log/channels.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::logs {

struct TiltDecoderConfig {
  int nodeId = 5;
  int countsPerRev = 4096;
  double gearRatio = 50.0;
  long zeroOffsetCounts = 0;

  canopen::TiltUnits units() const;
  double countsToRad(std::int32_t counts) const;
  std::int32_t radToCounts(double rad) const;
};

struct TiltDecoderCounters {
  std::uint64_t positions = 0, syncs = 0, heartbeats = 0, malformed = 0, other = 0;
  std::uint8_t lastState = 0xFF;  // last heartbeat state byte (0x05 operational); 0xFF none yet
};

class TiltDecoder {
 public:
  explicit TiltDecoder(TiltDecoderConfig config = {}) : config_(config) {}
  std::optional<TiltSample> decode(const CanMessage& frame);
  const TiltDecoderCounters& counters() const { return counters_; }

 private:
  TiltDecoderConfig config_;
  TiltDecoderCounters counters_;
  std::optional<TiltSample> last_;
};

}  // namespace fusedet::drivers::logs
