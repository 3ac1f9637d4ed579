// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/sweep_assembler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

namespace fusedet::fusion {
namespace {
Stamp lastBeamStamp(const drivers::LaserScan& s) {
  return s.size() == 0 ? s.stamp : s.beamStamp(s.size() - 1);
}
}  // namespace

SweepAssembler::SweepAssembler(SweepConfig config)
    : config_(std::move(config)),
      windowNs_(static_cast<std::int64_t>(config_.tiltWindowS * 1e9)),
      maxSweepNs_(static_cast<std::int64_t>(config_.maxSweepS * 1e9)) {
  if (!(config_.tiltAxis.norm() > 0)) throw std::invalid_argument("sweep: tilt axis must not be zero");
  config_.tiltAxis.normalize();
  if (!(config_.tiltWindowS > 0)) throw std::invalid_argument("sweep: tilt window must be > 0");
  if (!(config_.remissionFullScale > 0)) throw std::invalid_argument("sweep: remission full scale must be > 0");
  if (!(config_.maxSweepS > config_.tiltWindowS) || !std::isfinite(config_.maxSweepS))
    throw std::invalid_argument("sweep: max sweep duration must be finite and longer than the tilt window");
  if (config_.maxSweepPoints == 0) throw std::invalid_argument("sweep: max sweep points must be > 0");
}

void SweepAssembler::addTilt(const drivers::TiltSample& sample) {
  ++stats_.tiltSamples;
  if (!std::isfinite(sample.angle)) {
    ++stats_.tiltOutOfOrder;
    return;
  }
  if (!tilt_.empty() && sample.stamp <= tilt_.back().stamp) {
    ++stats_.tiltOutOfOrder;
    // Far behind the newest sample: the newest may be the one off (a clock step). Enough samples
    // in order among themselves decide it: the history is dropped and they continue it.
    const bool farBehind = tilt_.back().stamp - sample.stamp > maxSweepNs_;
    const bool continuesRun = behind_.empty() || sample.stamp > behind_.back().stamp;
    if (!farBehind) {
      behind_.clear();
      return;
    }
    if (!continuesRun) behind_.clear();
    behind_.push_back(sample);
    if (behind_.size() < static_cast<std::size_t>(kClockStepConfirm)) return;
    ++stats_.tiltClockSteps;
    stats_.tiltOutOfOrder -= behind_.size();
    tilt_.assign(behind_.begin(), behind_.end());
    behind_.clear();
    stillFrom_ = tilt_.front();
    for (const drivers::TiltSample& s : tilt_)
      if (std::abs(s.angle - stillFrom_->angle) >= config_.minTiltChange) stillFrom_ = s;
    process(false);
    return;
  }
  behind_.clear();
  tilt_.push_back(sample);
  if (!stillFrom_ || std::abs(sample.angle - stillFrom_->angle) >= config_.minTiltChange) stillFrom_ = sample;
  process(false);
}

void SweepAssembler::addScan(const drivers::LaserScan& scan) {
  ++stats_.scans;
  newestScan_ = std::max(newestScan_, lastBeamStamp(scan));
  if (newestStart_) {
    // Scans out of order or repeated make the gap <= 0, which turns closing on tilt off.
    const std::int64_t gap = scan.stamp - *newestStart_;
    minScanGapNs_ = minScanGapNs_ ? std::min(*minScanGapNs_, gap) : gap;
  }
  newestStart_ = scan.stamp;
  newestSpanNs_ = lastBeamStamp(scan) - scan.stamp;
  reversalRefuted_ = false;
  pending_.push_back(scan);
  process(false);
}

bool SweepAssembler::tiltAt(Stamp t, double& angle) const {
  // First sample at or after t; the one before it must be at or before t.
  auto after = std::lower_bound(tilt_.begin(), tilt_.end(), t,
                                [](const drivers::TiltSample& s, Stamp v) { return s.stamp < v; });
  if (after == tilt_.end() || after->stamp - t > windowNs_) return false;
  if (after->stamp == t) {
    angle = after->angle;
    return true;
  }
  if (after == tilt_.begin()) return false;
  const auto before = std::prev(after);
  if (t - before->stamp > windowNs_) return false;
  const double f = static_cast<double>(t - before->stamp) / static_cast<double>(after->stamp - before->stamp);
  angle = before->angle + f * (after->angle - before->angle);
  return true;
}

void SweepAssembler::process(bool final) {
  while (!pending_.empty()) {
    const drivers::LaserScan& scan = pending_.front();
    const Stamp last = lastBeamStamp(scan);
    const bool tiltCovers = !tilt_.empty() && tilt_.back().stamp >= last;
    // Without tilt data up to the scan's end, wait - unless later scans show the tilt stream is
    // behind by more than the window (or the stream ended): then it can never be interpolated.
    if (!tiltCovers && !final && newestScan_ - last <= windowNs_) break;
    std::vector<double> angles(scan.size());
    bool ok = tiltCovers || scan.size() == 0;
    for (std::size_t i = 0; ok && i < scan.size(); ++i) ok = tiltAt(scan.beamStamp(i), angles[i]);
    if (ok && scan.size() > 0)
      useScan(scan, angles);
    else
      ++stats_.scansDroppedNoTilt;
    pending_.pop_front();
    reversalRefuted_ = false;  // the next scan and the sweep's last tilt may have changed
  }
  // Keep the tilt history the pending scans (and late ones) can still need.
  // While the laser is silent that would be everything: never more than maxSweepS behind the
  // newest sample.
  const Stamp keepFrom = std::max((pending_.empty() ? newestScan_ : pending_.front().stamp) - 2 * windowNs_,
                                  tilt_.empty() ? Stamp{} : tilt_.back().stamp - maxSweepNs_);
  while (tilt_.size() > 2 && tilt_[1].stamp < keepFrom) tilt_.pop_front();
  stats_.tiltStillS = stillFrom_ && newestScan_ > stillFrom_->stamp
                          ? static_cast<double>(newestScan_ - stillFrom_->stamp) * 1e-9
                          : 0.0;
  if (final) {
    closeSweep();
  } else if (config_.closeOnTilt && tiltProvesReversal()) {
    closeSweep();
    ++stats_.sweepsClosedOnTilt;
  }
}

// True when no scan still to come can join the open sweep. useScan() starts a new sweep with a
// scan whose tilt moves against the direction by minTiltChange inside it, or - moving less than
// that inside it - since the last used scan's last beam (a pause closes the sweep anyway). So
// every possible start s >= `next` of the next scan must give such a scan, judged on the tilt
// the samples give (interpolated up to the newest one) and, beyond the newest sample, on the
// assumption that the motor moves on against the direction at least as fast as between the
// last two samples (it has just turned and accelerates, or cruises). Both changes are piecewise
// linear in s with corners where s or s + span meets a sample, so checking the corners suffices.
bool SweepAssembler::tiltProvesReversal() {
  if (reversalRefuted_ || !hasOpen_ || direction_ == 0 || !lastTilt_ || tilt_.size() < 2 || !newestStart_ ||
      !minScanGapNs_ || *minScanGapNs_ <= 0)
    return false;
  // A received scan waiting for tilt data is the next one; otherwise the next starts no earlier
  // than the newest stamp plus the shortest gap seen between scan stamps.
  const Stamp next = pending_.empty() ? *newestStart_ + *minScanGapNs_ : pending_.front().stamp;
  const drivers::TiltSample& newest = tilt_.back();
  const drivers::TiltSample& before = tilt_[tilt_.size() - 2];
  if (newest.stamp - next > static_cast<std::int64_t>(config_.maxScanGapS * 1e9)) {
    reversalRefuted_ = true;  // a scan after this long a pause closes the sweep by the pause rule
    return false;
  }
  // Against the direction = positive from here on.
  const double d = -static_cast<double>(direction_);
  const double lastSlope = d * (newest.angle - before.angle) / static_cast<double>(newest.stamp - before.stamp);
  if (!(lastSlope > 0)) return false;  // the newest interval does not (yet) show the reversal
  const double theta = config_.minTiltChange;
  bool exact = true;  // false once a tilt value beyond the newest sample was needed
  auto tilt = [&](Stamp t, double& out) {
    if (t > newest.stamp) {
      exact = false;
      out = d * newest.angle + lastSlope * static_cast<double>(t - newest.stamp);
      return true;
    }
    double a = 0;
    if (!tiltAt(t, a)) return false;
    out = d * a;
    return true;
  };
  // Corners: next, every sample and sample - span after it up to the newest sample, and the newest
  // sample itself (beyond it both changes only grow).
  std::vector<Stamp> corners{next};
  for (auto it = tilt_.rbegin(); it != tilt_.rend() && it->stamp > next; ++it)
    for (const Stamp c : {it->stamp, it->stamp - newestSpanNs_})
      if (c > next) corners.push_back(c);
  std::sort(corners.begin(), corners.end());
  const double last = d * *lastTilt_;
  bool prevIn = false, prevSince = false;
  for (std::size_t k = 0; k < corners.size(); ++k) {
    exact = true;
    double a0 = 0, a1 = 0;
    if (!tilt(corners[k], a0) || !tilt(corners[k] + newestSpanNs_, a1)) return false;
    const bool forward = -(a1 - a0) >= theta;   // the scan would keep the sweep's direction
    const bool in = a1 - a0 >= theta;           // against it inside the scan
    const bool since = a1 - last >= theta;      // against it since the sweep's last beam
    // Between two corners both changes are linear: the reversal holds on the whole piece if one
    // of the two measures holds at both of its ends.
    const bool pieceOk = k == 0 || (in && prevIn) || (since && prevSince);
    if (forward || !(in || since) || !pieceOk) {
      if (exact) reversalRefuted_ = true;  // decided by samples alone: stays so until a scan comes
      return false;
    }
    prevIn = in;
    prevSince = since;
  }
  return true;
}

void SweepAssembler::useScan(const drivers::LaserScan& scan, const std::vector<double>& tilt) {
  const bool pause = hasOpen_ && scan.stamp - lastBeam_ > static_cast<std::int64_t>(config_.maxScanGapS * 1e9);
  double change = tilt.back() - tilt.front();
  // Interlaced LMS scans (0.5 and 0.25 deg modes) put every beam at the scan's stamp
  // (beamDuration 0), so the tilt does not change inside them: the direction then comes from
  // the tilt since the previous scan (without this the default 180/0.5 mode never closed a sweep).
  if (std::abs(change) < config_.minTiltChange && lastTilt_ && !pause) change = tilt.back() - *lastTilt_;
  const int dir = std::abs(change) < config_.minTiltChange ? 0 : (change > 0 ? 1 : -1);
  const bool reversal = dir != 0 && direction_ != 0 && dir != direction_;
  if (reversal || pause) closeSweep();
  // No reversal for too long (tilt parked or stuck, or far too slow): not a nod. Cut, so that
  // memory stays bounded, and start afresh with this scan.
  if (hasOpen_ && (lastBeamStamp(scan) - open_.start > maxSweepNs_ ||
                   open_.points.size() + scan.size() > config_.maxSweepPoints))
    cutSweep();
  if (dir != 0) direction_ = dir;
  if (!hasOpen_) {
    open_ = Sweep{};
    open_.id = nextId_++;
    open_.frame = Sweep::Frame::kRobot;
    open_.start = scan.stamp;
    hasOpen_ = true;
  }
  ++stats_.scansUsed;
  const bool haveRemission = scan.remissions.size() == scan.size();
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double r = scan.ranges[i];
    if (!std::isfinite(r) || r < config_.minRange || r > config_.maxRange) continue;
    const double a = scan.beamAngle(i);
    const Eigen::Vector3d ps(r * std::sin(a), -r * std::cos(a), 0);
    const Eigen::Vector3d pb = Eigen::AngleAxisd(tilt[i], config_.tiltAxis) * (ps + config_.tiltAxisOffset);
    const Eigen::Vector3d p = config_.baseToRobot * pb;
    SweepPoint sp;
    sp.x = static_cast<float>(p.x());
    sp.y = static_cast<float>(p.y());
    sp.z = static_cast<float>(p.z());
    sp.remission = haveRemission
                       ? std::clamp(static_cast<float>(scan.remissions[i] / config_.remissionFullScale), 0.f, 1.f)
                       : 0.f;
    sp.stampNs = scan.beamStamp(i).ns;
    open_.points.push_back(sp);
  }
  lastBeam_ = lastBeamStamp(scan);
  lastTilt_ = tilt.back();
  open_.end = lastBeam_;
}

void SweepAssembler::closeSweep() {
  if (!hasOpen_) return;
  ++stats_.sweeps;
  stats_.points += open_.points.size();
  done_.push_back(std::move(open_));
  open_ = Sweep{};
  hasOpen_ = false;
}

void SweepAssembler::cutSweep() {
  ++stats_.sweepsCut;
  open_ = Sweep{};
  hasOpen_ = false;
}

std::vector<Sweep> SweepAssembler::takeSweeps() {
  std::vector<Sweep> out;
  out.swap(done_);
  return out;
}

void SweepAssembler::flush() { process(true); }

}  // namespace fusedet::fusion
