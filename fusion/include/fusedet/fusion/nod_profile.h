#pragma once
// NodProfile: the tilt angle of a nodding unit over time - back and forth between two angles at a
// cruise speed with limited acceleration (the trapezoidal profile a CiA 402 drive runs in
// profile position mode). Starts at `min` at t = 0, reaches `max` after one half period.

namespace fusedet::fusion {

struct NodProfile {
  double min = 0, max = 0;  // [rad]
  double speed = 0;         // [rad/s] cruise
  double accel = 0;         // [rad/s^2]

  // Time for one stroke min -> max (or back).
  double halfPeriod() const;
  double angleAt(double t) const;     // [rad], t [s] >= 0
  double velocityAt(double t) const;  // [rad/s]
};

}  // namespace fusedet::fusion
