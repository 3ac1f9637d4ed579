// SPDX-License-Identifier: Apache-2.0
// The pipeline fuses a sweep as soon as a tilt sample closes it (SweepAssembler closeOnTilt):
// the fusion thread takes sweeps after every message, tilt samples included, so the stack does
// not wait for the next stroke's first scan. Streams from a triangle tilt profile written here.

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>

#include "fusedet/daemon/pipeline.h"
#include "pipeline_fixtures.h"

using namespace fusedet;
using namespace fusedet::daemon;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr std::int64_t kT0 = 5'000'000'000;
constexpr std::int64_t kScanNs = 13'333'333;   // 75 Hz
constexpr std::int64_t kSpanNs = 6'600'000;    // first to last beam
constexpr int kBeams = 21;
constexpr int kLastUp = 19;                    // scans 0-19 rise, the peak is after 19's last beam
constexpr std::int64_t kPeak = kT0 + kLastUp * kScanNs + kSpanNs + 1'000'000;

double tiltAt(std::int64_t ns) {  // rad: up at 40 deg/s to the peak, then down at 40 deg/s
  return (10 - 40 * std::abs(static_cast<double>(ns - kPeak)) * 1e-9) * kPi / 180;
}

drivers::LaserScan scan(int n) {
  drivers::LaserScan s;
  s.stamp = Stamp{kT0 + n * kScanNs};
  s.sequence = static_cast<std::uint64_t>(n);
  s.startAngle = 40 * kPi / 180;
  s.angleStep = 5 * kPi / 180;
  s.beamDuration = static_cast<double>(kSpanNs) * 1e-9 / (kBeams - 1);
  s.ranges.assign(kBeams, 4.f);
  return s;
}

class NoDetections : public StackDetector {
 public:
  std::vector<Detection> detect(const LayerStack&) const override { return {}; }
  std::vector<std::string> classes() const override { return {"none"}; }
};

// Feeds everything a device would have delivered up to (not including) `until`: tilt samples at
// 100 Hz (5 ms phase) when stamped, scans 8 ms after their last beam (telegram), one camera frame
// at the stroke's middle. Returns the pipeline's results after it went idle.
std::vector<StackResult> feedUntil(bool closeOnTilt, std::int64_t until, PipelineCounters& counters) {
  const fusion::CameraModel camera = fixtures::pinholeCamera(64, 48, 50);
  PipelineSetup setup;
  setup.fuser = std::make_shared<const fusion::Fuser>(camera, Eigen::Isometry3d::Identity());
  setup.sweep.closeOnTilt = closeOnTilt;
  fixtures::Results results;
  Pipeline pipeline(setup, std::make_shared<NoDetections>(), results.handler());
  pipeline.start();
  drivers::CameraFrame frame;
  frame.stamp = Stamp{kT0 + kLastUp * kScanNs / 2};
  frame.width = camera.width;
  frame.height = camera.height;
  frame.stride = 3 * camera.width;
  frame.bytes.assign(static_cast<std::size_t>(frame.stride * frame.height), 100);
  bool frameSent = false;
  std::int64_t tilt = kT0 - 15'000'000;
  int n = 0;
  for (;;) {
    const std::int64_t scanArrives = kT0 + n * kScanNs + kSpanNs + 8'000'000;
    const std::int64_t next = std::min(tilt, scanArrives);
    if (next >= until) break;
    if (!frameSent && frame.stamp.ns <= next) {
      pipeline.onFrame(frame);
      frameSent = true;
    }
    if (tilt <= scanArrives) {
      pipeline.onTilt(drivers::TiltSample{Stamp{tilt}, tiltAt(tilt), 0});
      tilt += 10'000'000;
    } else {
      pipeline.onScan(scan(n++));
    }
  }
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!pipeline.idle() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  counters = pipeline.counters();
  pipeline.stop(std::chrono::steady_clock::now() + std::chrono::seconds(2));
  return results.all();
}
}  // namespace

TEST(PipelineClose, ASweepClosedByATiltSampleIsFusedBeforeTheNextScanArrives) {
  // Scan 19 ends at 259.9 ms, 1 ms before the peak; the samples at 255 and 265 ms straddle the
  // peak, the one at 275 ms ends the first falling interval. Scan 20 (falling) starts at
  // 266.7 ms and arrives at 281.3 ms. Feed everything before that.
  const std::int64_t scan20Arrives = kT0 + 20 * kScanNs + kSpanNs + 8'000'000;
  PipelineCounters counters;
  const auto onTilt = feedUntil(true, scan20Arrives, counters);
  ASSERT_EQ(onTilt.size(), 1u) << "the sweep of scans 0-19 was fused and detected";
  EXPECT_EQ(onTilt[0].sweepStart, Stamp{kT0});
  EXPECT_EQ(onTilt[0].sweepEnd, Stamp{kT0 + kLastUp * kScanNs + kSpanNs});
  EXPECT_EQ(counters.sweeps.sweepsClosedOnTilt, 1u);
  EXPECT_EQ(counters.sweeps.scansUsed, 20u);
  EXPECT_EQ(counters.unpaired, 0u);
  // Without closeOnTilt the same messages leave the sweep open: scan 20 has not arrived.
  const auto onScan = feedUntil(false, scan20Arrives, counters);
  EXPECT_TRUE(onScan.empty());
  EXPECT_EQ(counters.sweeps.sweeps, 0u);
}
