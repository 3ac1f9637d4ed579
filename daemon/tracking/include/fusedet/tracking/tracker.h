// SPDX-License-Identifier: Apache-2.0
#pragma once
// Tracker: the multi-object track manager after detection. Per stack (with its stamp) it takes
// the detections with a laser-measured 3D position in the robot frame, predicts every live track
// to the stack's stamp (constant-velocity Kalman filter, kalman.h), associates detections with
// tracks of the same class by an optimal assignment (assignment.h) on the squared Mahalanobis
// distance within a gate, corrects the matched tracks, starts a tentative track at every
// unmatched detection and lets tracks die:
// - birth: a tentative track is confirmed once it was detected in birthHits of its first
//   birthWindow stacks (M of N); it dies as soon as it can no longer reach that;
// - death: a confirmed track dies after more than maxMisses consecutive stacks without a detection;
//   any track whose last detection is more than maxCoastS seconds older than a stack ends before
//   that stack's association (a gap in the stacks: its prediction is too uncertain to take one);
// - ids count up from 1 and are never given twice by one Tracker, also across reset().
// Time comes only from the stamps: any rate, gaps, dropped stacks and replays at any speed work
// alike; a stamp older than the previous one (a log replayed again from its start) ends every
// track, as reset() does.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/core/box.h"
#include "fusedet/core/stamp.h"
#include "fusedet/tracking/kalman.h"

namespace fusedet::tracking {

struct TrackerParams {
  KalmanNoise noise;
  double gate = 11.34;    // squared Mahalanobis distance (chi-square, 3 dof, 0.99)
  int birthHits = 2;      // M: detections needed ...
  int birthWindow = 3;    // N: ... within a tentative track's first N stacks
  int maxMisses = 3;      // a confirmed track survives this many consecutive stacks without a detection
  double maxCoastS = 3.0; // and dies when its last detection is older than this [s]
};
// Throws std::invalid_argument naming the parameter that is out of range.
void validate(const TrackerParams& params);

// One detection as the tracker sees it.
struct Observation {
  std::string className;
  std::optional<Eigen::Vector3d> position;  // robot frame [m]; without one it is not tracked
  Box box;                                  // image pixels (kept as the track's latest box)
};

struct TrackState {
  std::uint64_t id = 0;
  std::string className;
  bool confirmed = false;
  bool coasting = false;   // not detected in this stack (position predicted)
  Eigen::Vector3d position = Eigen::Vector3d::Zero();  // robot frame [m], filtered
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();  // robot frame [m/s]
  double positionSigma = 0;  // sqrt of the mean positional variance [m]
  Stamp born, lastDetected;
  double ageS = 0;       // seconds from the first detection to this stack
  int stacks = 0;        // stacks seen since birth, this one included
  int hits = 0;          // of those, with a detection
  int misses = 0;        // consecutive stacks without a detection, up to this one
  Box box;               // the latest detection's box
};

struct TrackedStack {
  // Per observation (same order): index into `tracks`, or -1 (no position: not tracked).
  std::vector<int> trackOf;
  // Every live track after this stack, ascending id (tentative, confirmed and coasting ones).
  std::vector<TrackState> tracks;
};

class Tracker {
 public:
  explicit Tracker(TrackerParams params = {});

  TrackedStack update(Stamp stamp, const std::vector<Observation>& observations);
  // Ends every track; ids keep counting.
  void reset();

  const TrackerParams& params() const { return params_; }
  std::size_t liveTracks() const { return tracks_.size(); }

 private:
  struct Track {
    TrackState state;
    ConstantVelocityKalman filter;
  };
  void associate(const std::vector<Observation>& observations, std::vector<int>& trackOfObservation) const;
  static void publish(Track& t);

  TrackerParams params_;
  std::vector<Track> tracks_;  // ascending id
  std::optional<Stamp> last_;
  std::uint64_t nextId_ = 1;
};

}  // namespace fusedet::tracking
