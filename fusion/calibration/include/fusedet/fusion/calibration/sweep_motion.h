// SPDX-License-Identifier: Apache-2.0
#pragma once
// The scanner's own motion during a sweep. A spinning laser (KITTI's Velodyne HDL-64E: one turn in
// 0.1 s) measures each point from where it was when its beam fired; KITTI's raw sweeps are not
// corrected for that, so on a moving car a sweep is sheared against the image, which the camera
// took at one instant (triggered when the laser faces forward). Calibrating on such sweeps mistakes
// the shear for an error of the extrinsics (docs/results, "Calibration").
// Here: the planar motion between two sweeps of the same drive (scan matching), and a sweep moved
// into the scanner's frame at the instant it faced forward.

#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

// Velocity in the plane of the sweep's frame (x ahead, y left, z up; KITTI's Velodyne frame).
struct PlanarMotion {
  double vx = 0, vy = 0;  // [m/s]
  double yawRate = 0;     // [rad/s], counter-clockwise seen from above
};

struct PlanarMatchOptions {
  double minRange = 4, maxRange = 40;  // [m] horizontal range of the points matched
  double minHeight = -1.4;             // [m] lower points (the road under a sensor 1.73 m up) are left out
  double maxPairDistance = 1.0;        // [m] farther nearest neighbours are no pair
  int stride = 3;                      // every stride-th point of the later sweep is matched
  int iterations = 40;
};

// The motion that carries `earlier`'s frame onto `later`'s, divided by `seconds` between them:
// point-to-point ICP over x, y and yaw of `later`'s points against `earlier`'s (nearest neighbours
// on a grid). Throws std::invalid_argument when fewer than 100 pairs remain.
PlanarMotion estimatePlanarMotion(const Sweep& earlier, const Sweep& later, double seconds,
                                  const PlanarMatchOptions& options = {});

// Which way the beam turns, seen from above. The HDL-64E turns clockwise: a point's azimuth
// (atan2(y, x)) falls with its time.
enum class SpinSense { kClockwise, kCounterClockwise };

// Moves every point of a sweep of one turn of `turnSeconds` into the scanner's frame at the instant
// its beam pointed ahead (azimuth 0), under constant `motion`: a point at azimuth a was measured
// a / (2 pi) turns later (counter-clockwise) or earlier (clockwise) than that instant.
void deskewSweep(Sweep& sweep, const PlanarMotion& motion, double turnSeconds, SpinSense sense = SpinSense::kClockwise);

}  // namespace fusedet::fusion
