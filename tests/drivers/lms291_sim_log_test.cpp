// SPDX-License-Identifier: Apache-2.0
// lms291-sim --log: the simulator streams a synthesised log's scans (re-encoded by its own
// encoder) and the live driver on the pty reads exactly those scans, in order, looping at the end;
// a driver asking for another scan mode than the log's is refused.
// The expected scans come from this test's own replay of the log, configured from the
// synthesiser's rig values (not from the simulator's reading of the log's metadata).

#include <gtest/gtest.h>
#include <stdlib.h>

#include <chrono>
#include <cmath>
#include <filesystem>

#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/synthesis/synth_log.h"
#include "log_scans.h"
#include "simulator.h"

using namespace fusedet::drivers::lms291;
using fusedet::drivers::LaserScan;
namespace logs = fusedet::drivers::logs;
namespace fs = std::filesystem;
using namespace std::chrono_literals;

namespace {

class LmsSimLog : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/lms291-log-test-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    log_ = dir_ / "procedural.mcap";
    fusedet::fusion::SynthOptions o;  // procedural scene: no KITTI needed
    o.frames = 2;
    fusedet::fusion::synthesizeLog(o, log_);
    const fusedet::fusion::SynthRig rig;
    mode_ = Variant{rig.angleDeg, rig.resolutionCdeg};
    // The log's scans as the driver's decoder reads the raw serial channel.
    Lms291Config c;
    c.variant = mode_;
    c.remission = true;
    c.measuringMode = kMeasuringRemission;
    c.unit = Unit::kCm;
    logs::SensorReplay replay(log_, logs::SensorReplayConfig{c, {}});
    logs::SensorReplay::Handlers h;
    h.scan = [&](const LaserScan& s) { expected_.push_back(s); };
    replay.run(h);
    ASSERT_GT(expected_.size(), 100u);
  }
  void TearDown() override {
    sim_.reset();
    fs::remove_all(dir_);
  }
  void startSim() {
    auto scans = sim::loadLoggedScans(log_);
    ASSERT_TRUE(scans) << scans.error().message();
    sim::SimOptions o;
    o.link = (dir_ / "tty").string();
    o.powerOnBaud = 500000;
    o.variant = scans->variant;
    o.log = std::make_shared<const sim::LoggedScans>(std::move(*scans));
    sim_ = std::make_unique<sim::Simulator>(std::move(o));
    auto r = sim_->start();
    ASSERT_TRUE(r) << r.error().message();
  }
  Lms291Config driverConfig(Variant v, Unit unit) const {
    Lms291Config c;
    c.device = (dir_ / "tty").string();
    c.baud = 500000;
    c.variant = v;
    c.remission = true;
    c.unit = unit;
    c.baudSwitchPause = 50ms;
    return c;
  }
  fs::path dir_, log_;
  Variant mode_;
  std::vector<LaserScan> expected_;
  std::unique_ptr<sim::Simulator> sim_;
};

bool sameScan(const LaserScan& a, const LaserScan& b) { return a.ranges == b.ranges && a.remissions == b.remissions; }

TEST_F(LmsSimLog, DriverReadsTheLogsScansInOrderAndLooping) {
  startSim();
  Lms291 lms(driverConfig(mode_, Unit::kCm));
  auto info = lms.start();
  ASSERT_TRUE(info) << info.error().message();
  const std::size_t n = expected_.size();
  const std::size_t count = n + 40;  // past the end: the stream starts again with the log's first scan
  std::size_t first = n, valid = 0, beams = 0;
  for (std::size_t i = 0; i < count; ++i) {
    auto s = lms.readScan(1000ms);
    ASSERT_TRUE(s) << "scan " << i << ": " << s.error().message();
    if (i == 0) {
      // Initialisation may have taken a single scan (0x30 01): find where the stream begins.
      for (std::size_t k = 0; k < n && first == n; ++k)
        if (sameScan(*s, expected_[k])) first = k;
      ASSERT_LT(first, 4u) << "the first streamed scan is none of the log's first scans";
    }
    const LaserScan& want = expected_[(first + i) % n];
    ASSERT_EQ(s->ranges.size(), want.ranges.size());
    for (std::size_t b = 0; b < want.ranges.size(); ++b) {
      ASSERT_EQ(s->ranges[b], want.ranges[b]) << "scan " << i << " (log scan " << (first + i) % n << ") beam " << b;
      ASSERT_EQ(s->remissions[b], want.remissions[b]) << "scan " << i << " beam " << b;
      valid += want.ranges[b] > 0;
      ++beams;
    }
  }
  std::printf("%zu scans read (log: %zu, from log scan %zu, looped once); %zu of %zu beams with a return, all equal\n",
              count, n, first, valid, beams);
  EXPECT_GT(valid, beams / 2) << "the log's scene is in range";
  EXPECT_EQ(lms.counters().lostScans, 0u);
  EXPECT_EQ(lms.counters().link.reader.crcErrors, 0u);
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSimLog, AnotherScanModeIsRefused) {
  startSim();
  {
    auto c = driverConfig({180, 100}, Unit::kCm);  // the log is 100 deg wide
    Lms291 lms(c);
    auto info = lms.start();
    EXPECT_FALSE(info) << "180 deg served from a 100 deg log";
  }
  {
    Lms291 lms(driverConfig(mode_, Unit::kMm));  // the log's ranges are in cm
    auto info = lms.start();
    EXPECT_FALSE(info) << "mm served from a cm log";
  }
  EXPECT_EQ(sim_->counters().scansOut, 0u);
}

}  // namespace
