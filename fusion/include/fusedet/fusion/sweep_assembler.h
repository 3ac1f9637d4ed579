// SPDX-License-Identifier: Apache-2.0
#pragma once
// SweepAssembler: LaserScan + TiltSample streams of a nodding SICK LMS -> 3D sweeps (design §4).
//
// Geometry: beam angle a (0 = right, pi/2 = ahead, counter-clockwise) and range r give
// p_s = r (sin a, -cos a, 0) in the scanner frame (x ahead, y left, z up). The scanner sits on the
// tilt axis at `tiltAxisOffset` (scanner frame, at tilt 0) and is rotated by the tilt angle about
// `tiltAxis` (right-hand rule): p_base = Rot(axis, tilt(t_beam)) (p_s + offset), then
// p = baseToRobot * p_base. With the default axis +y, a positive tilt turns the forward beam down.
//
// Time: the tilt angle is interpolated linearly at each beam's own stamp between the two tilt
// samples around it. A scan whose beams are not all bracketed by samples at most `tiltWindowS`
// away is dropped and counted - never extrapolated. Sweeps are split where the tilt direction
// reverses (and after a pause longer than `maxScanGapS`).
//
// Which scans belong to a sweep: a scan whose tilt moves against the sweep's direction (by at
// least `minTiltChange` within the scan, or - when it moves less inside itself, e.g. interlaced
// scans - since the previous used scan) starts the next sweep; scans at rest join the open one.
// When the sweep closes: with `closeOnTilt` as soon as the tilt samples prove that whatever scan
// comes next moves against the direction - for every start from the earliest the next scan can
// have (a received scan waiting for tilt: its stamp; else the newest stamp + the shortest gap
// seen between scan stamps) - so `addTilt` of that sample emits the sweep, up to a scan period
// plus a telegram before the next scan would have shown it. Beyond the newest sample the proof
// assumes the motor moves on against the direction at least as fast as between the last two
// samples (it has just turned: it accelerates or cruises), and that scans come in stamp order.
// Until the samples prove it (a scan may still start before the turn and straddle it, tilt
// stream late, missing or at rest, direction unknown, scans out of order) the sweep closes as
// without `closeOnTilt`: when the first scan against the direction is in. The assignment of
// scans to sweeps is the same either way.
//
// Bounds (a parked or faulted tilt motor while the laser scans): a scan at rest joins the open
// sweep, so without a reversal it would never close. An open sweep that would span more than
// `maxSweepS` or hold more than `maxSweepPoints` points is cut: dropped (not a nod: fusing it would
// give a stack of one laser line) and counted in `sweepsCut`; the scan starts the next sweep.
// Tilt samples older than `maxSweepS` before the newest one are forgotten even while the laser is
// silent (scans that late are dropped as having no tilt). `tiltStillS` says for how long the laser
// has scanned while the tilt stood still (the daemon's `status` shows it).
//
// Clock steps: SocketCAN stamps frames in CLOCK_REALTIME and the bus moves them to the monotonic
// clock at reception, so the frames received around a wall-clock step (NTP, an RTC set) carry a
// stamp off by the step. A tilt sample stamped far behind is ignored like any out-of-order one;
// one stamped far ahead used to make every later sample "out of order" until the clock reached
// it (an hour of no sweeps for a one-hour step). Now `kClockStepConfirm` consecutive samples in
// order among themselves but more than `maxSweepS` behind the newest one mean the history is on
// another time line: it is dropped and they start it afresh (counted in `tiltClockSteps`).

#include <Eigen/Geometry>
#include <cstdint>
#include <deque>
#include <optional>
#include <vector>

#include "fusedet/drivers/messages.h"
#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

struct SweepConfig {
  Eigen::Vector3d tiltAxisOffset{0, 0, 0.05};  // [m] scanner origin relative to the tilt axis
  Eigen::Vector3d tiltAxis{0, 1, 0};           // tilt axis direction in the base frame (normalised)
  Eigen::Isometry3d baseToRobot = Eigen::Isometry3d::Identity();
  double tiltWindowS = 0.05;         // max time from a beam to the tilt samples around it
  double remissionFullScale = 1.0;   // raw remission value that maps to 1 (1 = already normalised)
  double minRange = 0.05;            // [m] shorter returns are noise (LMS: dazzle, dirt on the window)
  double maxRange = 80.0;            // [m] longer returns are dropped
  double maxScanGapS = 1.0;          // a longer pause between scans closes the sweep
  double minTiltChange = 1e-5;       // [rad] over one scan; below it the direction is undecided
  bool closeOnTilt = true;           // close when the tilt proves the reversal (false: when the next scan shows it)
  double maxSweepS = 10.0;           // a longer open sweep is cut and dropped; also the tilt history kept
  std::size_t maxSweepPoints = 1'000'000;  // a sweep with more points is cut and dropped (24 MB)
};

struct SweepStats {
  std::uint64_t scans = 0;             // scans received
  std::uint64_t scansUsed = 0;         // scans turned into points
  std::uint64_t scansDroppedNoTilt = 0;  // no tilt samples within the window around some beam
  std::uint64_t tiltSamples = 0;
  std::uint64_t tiltOutOfOrder = 0;    // samples not newer than the last one, ignored
  std::uint64_t tiltClockSteps = 0;    // tilt history dropped: the samples came back from a stamp far ahead
  std::uint64_t sweeps = 0;            // sweeps completed
  std::uint64_t sweepsClosedOnTilt = 0;  // of these, closed by tilt samples before the next scan (closeOnTilt)
  std::uint64_t points = 0;            // points in completed sweeps
  std::uint64_t sweepsCut = 0;         // open sweeps over maxSweepS / maxSweepPoints, dropped
  double tiltStillS = 0;               // newest scan - when the tilt last moved (~a sample period while it moves)
};

class SweepAssembler {
 public:
  static constexpr int kClockStepConfirm = 3;  // samples that agree with each other, not with the history

  explicit SweepAssembler(SweepConfig config = {});

  void addTilt(const drivers::TiltSample& sample);
  void addScan(const drivers::LaserScan& scan);
  // Completed sweeps, oldest first; the assembler keeps none of them.
  std::vector<Sweep> takeSweeps();
  // End of stream: decides pending scans (dropping those the tilt data never reached) and closes
  // the open sweep.
  void flush();

  const SweepStats& stats() const { return stats_; }
  const SweepConfig& config() const { return config_; }

  // Tilt angle at time t interpolated from the samples around it, or false if there are none
  // within the window on both sides. Exposed for tests and diagnostics.
  bool tiltAt(Stamp t, double& angle) const;
  // Tilt samples kept (bounded by maxSweepS of history) and points in the open sweep.
  std::size_t tiltSamplesKept() const { return tilt_.size(); }
  std::size_t openPoints() const { return hasOpen_ ? open_.points.size() : 0; }

 private:
  void process(bool final);
  void useScan(const drivers::LaserScan& scan, const std::vector<double>& tilt);
  void closeSweep();
  void cutSweep();
  bool tiltProvesReversal();

  SweepConfig config_;
  std::int64_t windowNs_;
  std::int64_t maxSweepNs_;
  std::optional<drivers::TiltSample> stillFrom_;  // the sample the tilt has not moved away from since
  std::deque<drivers::TiltSample> tilt_;
  std::vector<drivers::TiltSample> behind_;  // consecutive samples far behind the history (a clock step?)
  std::deque<drivers::LaserScan> pending_;
  Stamp newestScan_{};             // last beam of the newest scan received
  std::optional<Stamp> newestStart_;  // first beam of the newest scan received
  std::optional<std::int64_t> minScanGapNs_;  // shortest gap between consecutive scan stamps seen
  std::int64_t newestSpanNs_ = 0;             // first to last beam of the newest scan
  bool reversalRefuted_ = false;  // the samples alone disproved it; stays until a scan comes or is decided
  Sweep open_;
  bool hasOpen_ = false;
  int direction_ = 0;  // +1 rising, -1 falling, 0 not yet known
  Stamp lastBeam_{};
  std::optional<double> lastTilt_;  // tilt at the last used scan's last beam
  std::uint64_t nextId_ = 0;
  std::vector<Sweep> done_;
  SweepStats stats_;
};

}  // namespace fusedet::fusion
