// SPDX-License-Identifier: Apache-2.0
#pragma once
// MotionProfile: the simulated drive's trajectory generator for profile position mode. Moves
// toward a target with a trapezoidal velocity profile: accelerate at most `accel`, cruise at
// most `vmax`, brake at most `decel` so as to stop on the target. Units: counts, counts/s.

namespace fusedet::drivers::canopen::sim {

class MotionProfile {
 public:
  void reset(double position) {
    position_ = position;
    target_ = position;
    velocity_ = 0;
    moving_ = false;
  }
  void setTarget(double target) {
    target_ = target;
    moving_ = true;
  }
  void stop() { stopping_ = true; }    // brake to standstill, then hold where it stopped
  void resume() { stopping_ = false; }
  // Advances by dt seconds with the given limits (all > 0).
  void step(double dt, double vmax, double accel, double decel);

  double position() const { return position_; }
  double velocity() const { return velocity_; }
  double target() const { return target_; }
  bool reached() const { return !moving_; }  // on target and at rest

 private:
  double position_ = 0;
  double velocity_ = 0;
  double target_ = 0;
  bool moving_ = false;
  bool stopping_ = false;
};

}  // namespace fusedet::drivers::canopen::sim
