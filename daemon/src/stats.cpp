// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/stats.h"

#include <algorithm>

#include "fusedet/core/percentile.h"

namespace fusedet::daemon {

void RateMeter::tick(std::int64_t nowNs) {
  std::lock_guard lock(mutex_);
  events_.push_back(nowNs);
  ++total_;
  expire(nowNs);
}

void RateMeter::expire(std::int64_t nowNs) const {
  while (!events_.empty() && events_.front() <= nowNs - windowNs_) events_.pop_front();
}

double RateMeter::rate(std::int64_t nowNs) const {
  std::lock_guard lock(mutex_);
  expire(nowNs);
  return static_cast<double>(events_.size()) / (static_cast<double>(windowNs_) * 1e-9);
}

std::uint64_t RateMeter::total() const {
  std::lock_guard lock(mutex_);
  return total_;
}

void LatencyRecorder::add(double ms) {
  std::lock_guard lock(mutex_);
  if (ring_.size() < capacity_) {
    ring_.push_back(ms);
  } else {
    ring_[next_] = ms;
    next_ = (next_ + 1) % capacity_;
  }
}

LatencySummary LatencyRecorder::summary() const {
  std::vector<double> v;
  {
    std::lock_guard lock(mutex_);
    v = ring_;
  }
  LatencySummary s;
  s.samples = v.size();
  if (v.empty()) return s;
  s.p50Ms = percentile(v, 0.5);
  s.p90Ms = percentile(v, 0.9);
  s.p99Ms = percentile(v, 0.99);
  s.maxMs = *std::max_element(v.begin(), v.end());
  return s;
}

}  // namespace fusedet::daemon
