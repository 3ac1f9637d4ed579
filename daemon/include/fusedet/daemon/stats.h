// SPDX-License-Identifier: Apache-2.0
#pragma once
// Small thread-safe meters for `status`: event rates over a sliding window and latency
// percentiles over the most recent samples.

#include <cstdint>
#include <deque>
#include <mutex>
#include <vector>

namespace fusedet::daemon {

// Events per second over the last `windowNs` (steady clock, nanoseconds).
class RateMeter {
 public:
  explicit RateMeter(std::int64_t windowNs = 5'000'000'000) : windowNs_(windowNs) {}
  void tick(std::int64_t nowNs);
  double rate(std::int64_t nowNs) const;
  std::uint64_t total() const;

 private:
  void expire(std::int64_t nowNs) const;
  std::int64_t windowNs_;
  mutable std::mutex mutex_;
  mutable std::deque<std::int64_t> events_;
  std::uint64_t total_ = 0;
};

struct LatencySummary {
  std::size_t samples = 0;
  double p50Ms = 0, p90Ms = 0, p99Ms = 0, maxMs = 0;
};

// Keeps the last `capacity` samples (milliseconds).
class LatencyRecorder {
 public:
  explicit LatencyRecorder(std::size_t capacity = 1024) : capacity_(capacity) {}
  void add(double ms);
  LatencySummary summary() const;

 private:
  std::size_t capacity_;
  mutable std::mutex mutex_;
  std::vector<double> ring_;
  std::size_t next_ = 0;
};

}  // namespace fusedet::daemon
