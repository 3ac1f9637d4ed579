// SPDX-License-Identifier: Apache-2.0
#pragma once
// TiltTpdoDecoder: the tilt motor's TPDO1 -> TiltSample. TiltDrive maps TPDO1 (COB-ID 0x180 +
// node, sent on every SYNC) as position actual value (0x6064, int32 LE) + statusword (0x6041,
// uint16 LE); the sample is stamped at the frame's reception, the angle comes from the counts
// (TiltUnits), the velocity from the previous sample when it is at most 0.5 s older.
// One rule in one place: the live drive and the log replay both decode with this class.

#include <cstdint>
#include <optional>

#include "fusedet/drivers/canopen/can_frame.h"
#include "fusedet/drivers/canopen/tilt_units.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::drivers::canopen {

struct TiltTpdo {
  TiltSample sample;
  std::uint16_t statusword = 0;
};

class TiltTpdoDecoder {
 public:
  TiltTpdoDecoder(int node, TiltUnits units) : node_(node), units_(units) {}

  // True for a data frame with the node's TPDO1 COB-ID (whatever its length).
  bool isTpdo(const CanFrame& f) const;
  // The sample of a TPDO1 frame; nullopt (counted as bad) when it carries fewer than 6 bytes.
  // Call only for frames isTpdo() accepts.
  std::optional<TiltTpdo> decode(const CanFrame& f);

  const std::optional<TiltSample>& last() const { return last_; }
  std::uint64_t samples() const { return samples_; }
  std::uint64_t badPdos() const { return badPdos_; }

 private:
  int node_;
  TiltUnits units_;
  std::optional<TiltSample> last_;
  std::uint64_t samples_ = 0, badPdos_ = 0;
};

}  // namespace fusedet::drivers::canopen
