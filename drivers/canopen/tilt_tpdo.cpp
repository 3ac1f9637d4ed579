// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/canopen/tilt_tpdo.h"

#include "fusedet/drivers/canopen/protocol.h"

namespace fusedet::drivers::canopen {

namespace {
constexpr std::int64_t kVelocityGapNs = 500'000'000;  // older samples say nothing about the speed now
}

bool TiltTpdoDecoder::isTpdo(const CanFrame& f) const {
  return !f.error && !f.rtr && !f.extended && f.id == cob::kTpdo1 + static_cast<std::uint32_t>(node_);
}

std::optional<TiltTpdo> TiltTpdoDecoder::decode(const CanFrame& f) {
  if (f.len < 6) {
    ++badPdos_;
    return std::nullopt;
  }
  TiltTpdo t;
  t.statusword = static_cast<std::uint16_t>(readLe(f.data, 4, 2));
  t.sample.stamp = f.stamp;
  t.sample.angle = units_.toRad(static_cast<std::int32_t>(readLe(f.data, 0, 4)));
  // Stamps from a log may lie anywhere in int64: a difference that does not fit is no recent sample.
  std::int64_t dt = 0;
  if (last_ && f.stamp > last_->stamp && !__builtin_sub_overflow(f.stamp.ns, last_->stamp.ns, &dt) && dt < kVelocityGapNs)
    t.sample.velocity = (t.sample.angle - last_->angle) / (static_cast<double>(dt) * 1e-9);
  last_ = t.sample;
  ++samples_;
  return t;
}

}  // namespace fusedet::drivers::canopen
