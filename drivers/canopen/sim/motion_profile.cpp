// SPDX-License-Identifier: Apache-2.0
#include "motion_profile.h"

#include <algorithm>
#include <cmath>

namespace fusedet::drivers::canopen::sim {

void MotionProfile::step(double dt, double vmax, double accel, double decel) {
  if (dt <= 0) return;
  if (stopping_ || !moving_) {
    // Brake to standstill (a halt, or a drive that was disabled while moving).
    const double dv = decel * dt;
    velocity_ = std::abs(velocity_) <= dv ? 0.0 : velocity_ - std::copysign(dv, velocity_);
    position_ += velocity_ * dt;
    if (stopping_ && velocity_ == 0.0) {
      target_ = position_;
      moving_ = false;
    }
    return;
  }
  const double remaining = target_ - position_;
  const double dir = remaining >= 0 ? 1.0 : -1.0;
  double v = velocity_ * dir;  // speed toward the target (negative = moving away)
  if (v < 0) {
    v = std::min(0.0, v + decel * dt);  // first brake the wrong-way motion
  } else {
    // Fastest speed from which the drive can still stop on the target.
    const double vStop = std::sqrt(2.0 * decel * std::abs(remaining));
    const double want = std::min(vmax, vStop);
    v = v < want ? std::min(want, v + accel * dt) : std::max(want, v - decel * dt);
  }
  const double moved = v * dt;
  if (v >= 0 && moved >= std::abs(remaining)) {  // arrives within this step
    position_ = target_;
    velocity_ = 0;
    moving_ = false;
    return;
  }
  position_ += moved * dir;
  velocity_ = v * dir;
}

}  // namespace fusedet::drivers::canopen::sim
