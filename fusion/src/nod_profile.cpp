#include "fusedet/fusion/nod_profile.h"

#include <algorithm>
#include <cmath>

namespace fusedet::fusion {

namespace {
// One stroke of length d: accelerate to v (or less, if d is short), cruise, decelerate.
struct Stroke {
  double v, a, tRamp, tCruise;
  explicit Stroke(const NodProfile& p) : a(p.accel) {
    const double d = p.max - p.min;
    v = std::min(p.speed, std::sqrt(d * a));
    tRamp = v / a;
    tCruise = (d - v * tRamp) / v;
  }
  double total() const { return 2 * tRamp + tCruise; }
  double distance(double t) const {
    if (t <= tRamp) return 0.5 * a * t * t;
    if (t <= tRamp + tCruise) return 0.5 * v * tRamp + v * (t - tRamp);
    const double u = std::min(t, total()) - tRamp - tCruise;
    return 0.5 * v * tRamp + v * tCruise + v * u - 0.5 * a * u * u;
  }
  double speed(double t) const {
    if (t <= tRamp) return a * t;
    if (t <= tRamp + tCruise) return v;
    return std::max(0.0, v - a * (t - tRamp - tCruise));
  }
};
}  // namespace

double NodProfile::halfPeriod() const { return Stroke(*this).total(); }

double NodProfile::angleAt(double t) const {
  const Stroke s(*this);
  const double h = s.total();
  const double k = std::floor(t / h);
  const double u = t - k * h;
  const bool rising = static_cast<long long>(k) % 2 == 0;
  return rising ? min + s.distance(u) : max - s.distance(u);
}

double NodProfile::velocityAt(double t) const {
  const Stroke s(*this);
  const double h = s.total();
  const double k = std::floor(t / h);
  const double u = t - k * h;
  return (static_cast<long long>(k) % 2 == 0 ? 1 : -1) * s.speed(u);
}

}  // namespace fusedet::fusion
