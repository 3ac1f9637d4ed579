#include "fusedet/fusion/sweep_assembler.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusedet::fusion {
namespace {
Stamp lastBeamStamp(const drivers::LaserScan& s) {
  return s.size() == 0 ? s.stamp : s.beamStamp(s.size() - 1);
}
}  // namespace

SweepAssembler::SweepAssembler(SweepConfig config)
    : config_(std::move(config)), windowNs_(static_cast<std::int64_t>(config_.tiltWindowS * 1e9)) {
  if (!(config_.tiltAxis.norm() > 0)) throw std::invalid_argument("sweep: tilt axis must not be zero");
  config_.tiltAxis.normalize();
  if (!(config_.tiltWindowS > 0)) throw std::invalid_argument("sweep: tilt window must be > 0");
  if (!(config_.remissionFullScale > 0)) throw std::invalid_argument("sweep: remission full scale must be > 0");
}

void SweepAssembler::addTilt(const drivers::TiltSample& sample) {
  ++stats_.tiltSamples;
  if (!tilt_.empty() && sample.stamp <= tilt_.back().stamp) {
    ++stats_.tiltOutOfOrder;
    return;
  }
  if (!std::isfinite(sample.angle)) {
    ++stats_.tiltOutOfOrder;
    return;
  }
  tilt_.push_back(sample);
  process(false);
}

void SweepAssembler::addScan(const drivers::LaserScan& scan) {
  ++stats_.scans;
  newestScan_ = std::max(newestScan_, lastBeamStamp(scan));
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
  }
  // Keep the tilt history the pending scans (and late ones) can still need.
  const Stamp keepFrom = (pending_.empty() ? newestScan_ : pending_.front().stamp) - 2 * windowNs_;
  while (tilt_.size() > 2 && tilt_[1].stamp < keepFrom) tilt_.pop_front();
  if (final) closeSweep();
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

std::vector<Sweep> SweepAssembler::takeSweeps() {
  std::vector<Sweep> out;
  out.swap(done_);
  return out;
}

void SweepAssembler::flush() { process(true); }

}  // namespace fusedet::fusion
