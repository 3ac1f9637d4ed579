// SPDX-License-Identifier: Apache-2.0
// The LMS 291 driver against lms291's simulator on a pseudo-terminal: initialisation from every
// start speed, lossless streaming, corruption, NAKs, vanish/reappear, stop back to 9600.
// Every scan is checked against the room geometry computed here, independently of the scene code.

#include <gtest/gtest.h>
#include <stdlib.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

#include "fusedet/drivers/lms291/lms291.h"
#include "fusedet/drivers/lms291/scan_stream.h"
#include "simulator.h"
#include "default_room.h"

using namespace fusedet::drivers::lms291;
using fusedet::drivers::LaserScan;
using Clock = std::chrono::steady_clock;
using namespace std::chrono_literals;

namespace {

double expectedRange(double deg) { return fusedet::testing::expectedRoomRange(deg); }

// Every beam (but the counter beam 0 when `counter`) matches the room to the millimetre.
::testing::AssertionResult matchesRoom(const LaserScan& s, bool counter) {
  for (std::size_t i = counter ? 1 : 0; i < s.size(); ++i) {
    const double deg = s.beamAngle(i) * 180.0 / M_PI;
    const double want = expectedRange(deg);
    if (std::abs(s.ranges[i] - want) > 0.0011)
      return ::testing::AssertionFailure() << "beam " << i << " (" << deg << " deg): " << s.ranges[i] << " m, room says "
                                           << want << " m";
  }
  return ::testing::AssertionSuccess();
}

// Sent-scan number carried by beam 0 (SimOptions::counterBeam): 1 m + n mm.
long counterOf(const LaserScan& s) { return std::lround(s.ranges[0] * 1000.0) - 1000; }

class LmsSim : public ::testing::Test {
 protected:
  void SetUp() override {
    char tmpl[] = "/tmp/lms291-test-XXXXXX";
    ASSERT_NE(mkdtemp(tmpl), nullptr);
    dir_ = tmpl;
    link_ = dir_ + "/tty";
  }
  void TearDown() override {
    sim_.reset();
    std::filesystem::remove_all(dir_);
  }
  sim::Simulator& startSim(sim::SimOptions o) {
    o.link = link_;
    sim_ = std::make_unique<sim::Simulator>(std::move(o));
    auto r = sim_->start();
    EXPECT_TRUE(r) << (r ? "" : r.error().message());
    return *sim_;
  }
  Lms291Config config(int baud, Variant v = {180, 50}) const {
    Lms291Config c;
    c.device = link_;
    c.baud = baud;
    c.variant = v;
    c.baudSwitchPause = 50ms;
    // A real LMS ACKs within 60 ms; the simulator is a thread that a loaded 2-core machine can
    // leave unscheduled for longer than stop()'s two 100 ms ACK waits (a bounded shutdown).
    c.ackTimeout = 300ms;
    return c;
  }
  std::optional<std::string> lateAnswerRun();
  std::string dir_, link_;
  std::unique_ptr<sim::Simulator> sim_;
};

TEST_F(LmsSim, InitialisesFromEveryStartBaudAndStopsAt9600) {
  for (int startBaud : {9600, 19200, 38400, 500000}) {
    SCOPED_TRACE("device starts at " + std::to_string(startBaud));
    sim::SimOptions o;
    o.powerOnBaud = startBaud;
    startSim(o);
    Lms291 lms(config(38400));
    auto info = lms.start();
    ASSERT_TRUE(info) << info.error().message();
    EXPECT_EQ(info->foundBaud, startBaud);
    EXPECT_EQ(info->type, "LMS291;S05");
    auto st = sim_->state();
    EXPECT_EQ(st.baud, 38400);
    EXPECT_EQ(st.hostBaud, 38400);
    EXPECT_TRUE(st.streaming);
    EXPECT_EQ(st.config[6], 1) << "units mm";
    auto scan = lms.readScan(2000ms);
    ASSERT_TRUE(scan) << scan.error().message();
    EXPECT_EQ(scan->size(), 361u);
    EXPECT_TRUE(matchesRoom(*scan, false));
    auto stopped = lms.stop();
    ASSERT_TRUE(stopped) << stopped.error().message();
    st = sim_->state();
    EXPECT_EQ(st.baud, 9600) << "after stop the device is back at 9600";
    EXPECT_FALSE(st.streaming);
    sim_.reset();
  }
}

TEST_F(LmsSim, FindsAStreamingDeviceAndTakesItOver) {
  sim::SimOptions o;
  startSim(o);
  {
    Lms291 first(config(500000, {180, 100}));
    ASSERT_TRUE(first.start());
    first.close();  // crash: device left streaming at 500 kbaud
  }
  Lms291 lms(config(38400));
  auto info = lms.start();
  ASSERT_TRUE(info) << info.error().message();
  EXPECT_EQ(info->foundBaud, 500000);
  auto scan = lms.readScan(2000ms);
  ASSERT_TRUE(scan);
  EXPECT_EQ(scan->size(), 361u);
  EXPECT_TRUE(lms.stop());
  EXPECT_EQ(sim_->state().baud, 9600);
}

TEST_F(LmsSim, Streams1000ScansNoneLostOrDuplicated) {
  sim::SimOptions o;
  o.counterBeam = true;
  startSim(o);
  auto c = config(500000, {180, 100});  // 75 scans/s: 1000 scans in ~13 s
  c.realTimeIndices = true;
  Lms291 lms(c);
  auto info = lms.start();
  ASSERT_TRUE(info) << info.error().message();
  long previous = -1;
  std::uint64_t previousSeq = 0;
  const auto t0 = Clock::now();
  fusedet::Stamp previousStamp, firstStamp;
  std::uint64_t skipped0 = 0;
  for (int i = 0; i < 1000; ++i) {
    auto s = lms.readScan(1000ms);
    ASSERT_TRUE(s) << "scan " << i << ": " << s.error().message();
    ASSERT_EQ(s->size(), 181u);
    const long n = counterOf(*s);
    if (previous >= 0) {
      // Every scan the simulator queued must arrive: it counts what it could not deliver.
      ASSERT_EQ(n, previous + 1) << "scan " << i << ": lost or duplicated; driver: " << lms.counters().link.reader.expired
                                 << " frames expired, " << lms.counters().link.reader.resyncs << " resyncs; simulator: "
                                 << sim_->counters().overrunBytes << " overrun bytes";
      ASSERT_EQ(s->sequence, previousSeq + 1);
      ASSERT_GT(s->stamp, previousStamp);
    }
    ASSERT_TRUE(matchesRoom(*s, true)) << "scan " << i;
    previous = n;
    previousSeq = s->sequence;
    previousStamp = s->stamp;
    if (i == 0) {
      firstStamp = s->stamp;
      skipped0 = sim_->counters().scansSkipped + sim_->counters().scansStalled;
    }
  }
  const double seconds = std::chrono::duration<double>(Clock::now() - t0).count();
  // 75 Hz mirror: stamps 13.33 ms apart on average, plus the rotations whose scan the device
  // skipped because the line was still busy (single intervals jitter with the load).
  const auto sc = sim_->counters();
  const double skipped = double(sc.scansSkipped + sc.scansStalled - skipped0);
  const double meanMs = double(previousStamp - firstStamp) * 1e-6 / 999.0;
  EXPECT_NEAR(meanMs, 1000.0 / 75 * (1000.0 + skipped) / 1000.0, 0.3) << skipped << " scans skipped";
  const auto k = lms.counters();
  std::printf(
      "1000 scans at 500000 baud in %.2f s, mean stamp interval %.3f ms; lost %llu, CRC errors %llu, resyncs %llu, "
      "expired frames %llu; simulator skipped %llu, stalled %llu, overrun bytes %llu\n",
      seconds, meanMs, (unsigned long long)k.lostScans, (unsigned long long)k.link.reader.crcErrors,
      (unsigned long long)k.link.reader.resyncs, (unsigned long long)k.link.reader.expired,
      (unsigned long long)sc.scansSkipped, (unsigned long long)sc.scansStalled, (unsigned long long)sc.overrunBytes);
  EXPECT_EQ(k.lostScans, 0u);
  EXPECT_EQ(k.link.reader.crcErrors, 0u);
  EXPECT_EQ(k.link.reader.expired, 0u) << "a telegram arrived with a gap inside";
  EXPECT_EQ(sc.overrunBytes, 0u);
  EXPECT_EQ(k.badScans, 0u);
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, OnePercentCorruptedBytesNeverYieldACorruptScan) {
  sim::SimOptions o;
  o.counterBeam = true;
  o.seed = 2024;
  startSim(o);
  auto c = config(500000, {100, 100});  // 212-byte telegrams: ~12 % survive 1 % byte errors
  c.realTimeIndices = true;
  Lms291 lms(c);
  ASSERT_TRUE(lms.start());
  // Settle, then corrupt 1 % of the bytes for 6 s, then clean again.
  for (int i = 0; i < 10; ++i) ASSERT_TRUE(lms.readScan(1000ms));
  sim::Faults f;
  f.bitFlipRate = 0.01;
  sim_->setFaults(f);
  std::vector<long> emitted;
  std::vector<long> corrupt;
  const auto until = Clock::now() + 6s;
  bool clean = false;
  int cleanScans = 0;
  while (cleanScans < 20) {
    if (!clean && Clock::now() > until) {
      sim_->setFaults(sim::Faults{});
      clean = true;
    }
    auto s = lms.readScan(1000ms);
    if (!s) {
      ASSERT_EQ(s.error().code, std::errc::timed_out) << s.error().message();
      continue;  // all scans of a second damaged is possible, just unlikely
    }
    ASSERT_EQ(s->size(), 101u);
    if (!matchesRoom(*s, true)) corrupt.push_back(counterOf(*s));
    emitted.push_back(counterOf(*s));
    if (clean) ++cleanScans;
  }
  const auto sc = sim_->counters();
  const auto damaged = sim_->damagedScans();
  const auto blind = sim_->crcBlindScans();
  const auto k = lms.counters();
  // Exact accounting over the window of emitted scans: every sent scan is emitted unless the
  // simulator damaged it (scans whose damage the LMS CRC cannot see are emitted, and counted).
  const long lo = emitted.front(), hi = emitted.back();
  std::set<long> damagedInWindow, blindInWindow;
  for (auto n : damaged)
    if (long(n) >= lo && long(n) <= hi) damagedInWindow.insert(long(n));
  for (auto n : blind)
    if (long(n) >= lo && long(n) <= hi) blindInWindow.insert(long(n));
  std::set<long> expected;
  for (long n = lo; n <= hi; ++n)
    if (!damagedInWindow.count(n) || blindInWindow.count(n)) expected.insert(n);
  const std::set<long> got(emitted.begin(), emitted.end());
  EXPECT_EQ(got.size(), emitted.size()) << "duplicates";
  std::printf(
      "1%% byte errors: sim sent %llu scans, damaged %llu (%llu bit flips), CRC-blind %zu; driver emitted %zu, "
      "corrupt %zu, lost (index gaps) %llu, CRC errors %llu, resyncs %llu, bad %llu\n",
      (unsigned long long)sc.scansOut, (unsigned long long)sc.scansDamaged, (unsigned long long)sc.bitFlips, blind.size(),
      emitted.size(), corrupt.size(), (unsigned long long)k.lostScans, (unsigned long long)k.link.reader.crcErrors,
      (unsigned long long)k.link.reader.resyncs, (unsigned long long)k.badScans);
  EXPECT_EQ(corrupt.size(), blindInWindow.size()) << "a corrupt scan got through that the CRC would have caught";
  if (blindInWindow.empty()) {
    EXPECT_TRUE(corrupt.empty());
  }
  // Counter numbers of corrupt scans may themselves be damaged: compare the rest exactly.
  if (corrupt.empty()) {
    EXPECT_EQ(got, expected);
  }
  EXPECT_GE(damagedInWindow.size(), 100u);  // the faults really happened
  // The driver's own lost-scan count (telegram-index gaps) matches what the simulator damaged
  // (the index byte of a CRC-blind scan can be wrong too: allow exactly those).
  const long lost = static_cast<long>(k.lostScans);
  const long damagedNotBlind = static_cast<long>(damagedInWindow.size() - blindInWindow.size());
  EXPECT_NEAR(lost, damagedNotBlind, 2.0 * blindInWindow.size() + 1.0);
  EXPECT_GE(k.link.reader.crcErrors, damagedNotBlind / 2);
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, GarbageDroppedBytesAndNaksAreSurvived) {
  sim::SimOptions o;
  o.counterBeam = true;
  startSim(o);
  Lms291 lms(config(500000, {180, 100}));
  sim_->nakStorm(2);  // the first two requests of the init are refused
  auto info = lms.start();
  ASSERT_TRUE(info) << info.error().message();
  auto k0 = lms.counters();
  EXPECT_EQ(k0.link.naks, 2u);
  EXPECT_GE(k0.link.retries, 2u);
  sim::Faults f;
  f.garbageRate = 0.3;
  f.dropRate = 0.0005;
  sim_->setFaults(f);
  int good = 0;
  for (int i = 0; i < 150; ++i) {
    auto s = lms.readScan(1000ms);
    ASSERT_TRUE(s) << s.error().message();
    ASSERT_TRUE(matchesRoom(*s, true));
    ++good;
  }
  sim_->setFaults({});
  const auto sc = sim_->counters();
  const auto k = lms.counters();
  std::printf("garbage %llu bytes, dropped %llu bytes -> %d good scans, %llu resyncs, %llu CRC errors\n",
              (unsigned long long)sc.garbageBytes, (unsigned long long)sc.droppedBytes, good,
              (unsigned long long)k.link.reader.resyncs, (unsigned long long)k.link.reader.crcErrors);
  EXPECT_GT(sc.garbageBytes, 0u);
  EXPECT_GT(k.link.reader.resyncs, 0u);
  // Stop works through a NAK storm too.
  sim_->nakStorm(1);
  EXPECT_TRUE(lms.stop());
  EXPECT_EQ(sim_->state().baud, 9600);
}

TEST_F(LmsSim, VanishAndReappearRecoversWithinTwoSeconds) {
  sim::SimOptions o;
  startSim(o);
  std::mutex m;
  std::vector<Clock::time_point> stamps;
  ScanStream stream(config(500000, {180, 100}), [&](const LaserScan& s) {
    EXPECT_TRUE(matchesRoom(s, false));
    std::lock_guard lock(m);
    stamps.push_back(Clock::now());
  });
  stream.start();
  auto waitScans = [&](std::size_t n, std::chrono::milliseconds limit) {
    const auto end = Clock::now() + limit;
    while (Clock::now() < end) {
      {
        std::lock_guard lock(m);
        if (stamps.size() >= n) return true;
      }
      std::this_thread::sleep_for(5ms);
    }
    return false;
  };
  ASSERT_TRUE(waitScans(20, 5s));
  std::size_t before;
  {
    std::lock_guard lock(m);
    before = stamps.size();
  }
  sim_->vanish(500ms);  // USB adapter unplugged for half a second
  const auto vanished = Clock::now();
  const auto reappeared = vanished + 500ms;
  ASSERT_TRUE(waitScans(before + 30, 6s)) << "no scans after reappearing";
  Clock::time_point firstAfter;
  {
    std::lock_guard lock(m);
    for (auto t : stamps)
      if (t > reappeared) {
        firstAfter = t;
        break;
      }
  }
  const double recovery = std::chrono::duration<double>(firstAfter - reappeared).count();
  const auto k = stream.counters();
  std::printf("vanish 0.5 s: first scan %.3f s after the port came back (%llu reconnects, %llu failed inits; last: %s)\n",
              recovery, (unsigned long long)k.reconnects, (unsigned long long)k.failedInits, k.lastError.c_str());
  EXPECT_LT(recovery, 2.0);
  EXPECT_EQ(k.reconnects, 1u);
  EXPECT_EQ(sim_->counters().vanishes, 1u);
  EXPECT_TRUE(stream.stop());
  EXPECT_EQ(sim_->state().baud, 9600);
  EXPECT_FALSE(sim_->state().streaming);
}

TEST_F(LmsSim, DeviceRestartIsNoticedAndFullyReinitialised) {
  sim::SimOptions o;
  startSim(o);
  std::atomic<int> scans{0};
  ScanStream stream(config(500000, {180, 100}), [&](const LaserScan&) { ++scans; }, 5000ms, 500ms);
  stream.start();
  const auto waitFor = [&](int n) {
    const auto end = Clock::now() + 5s;
    while (scans < n && Clock::now() < end) std::this_thread::sleep_for(5ms);
    return scans >= n;
  };
  ASSERT_TRUE(waitFor(10));
  sim_->powerCycle();  // back at 9600 in monitoring mode: the host at 500k hears nothing
  const auto restarted = Clock::now();
  const int before = scans;
  ASSERT_TRUE(waitFor(before + 5));
  const double recovery = std::chrono::duration<double>(Clock::now() - restarted).count();
  std::printf("device restart: streaming again after %.3f s (silence limit 0.5 s)\n", recovery);
  EXPECT_LT(recovery, 2.5);
  EXPECT_EQ(stream.counters().reconnects, 1u);
  EXPECT_EQ(sim_->state().baud, 500000);
  EXPECT_TRUE(stream.stop());
  EXPECT_EQ(sim_->state().baud, 9600);
}

TEST_F(LmsSim, SilenceTimesOutThenStreamingResumes) {
  sim::SimOptions o;
  startSim(o);
  Lms291 lms(config(500000, {180, 100}));
  ASSERT_TRUE(lms.start());
  ASSERT_TRUE(lms.readScan(1000ms));
  sim_->silence(600ms);
  // At most the scan already on the line arrives; then nothing.
  bool timedOut = false;
  for (int i = 0; i < 3 && !timedOut; ++i) {
    auto s = lms.readScan(150ms);
    if (!s) {
      EXPECT_EQ(s.error().code, std::errc::timed_out);
      timedOut = true;
    }
  }
  EXPECT_TRUE(timedOut);
  EXPECT_TRUE(lms.readScan(1500ms));
  EXPECT_GE(lms.counters().link.timeouts, 1u);
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, StopDuringASlowInitIsPrompt) {
  sim::SimOptions o;
  startSim(o);
  sim_->silence(10s);  // the device answers nothing: the init probes every speed
  ScanStream stream(config(38400), [](const LaserScan&) {});
  stream.start();
  std::this_thread::sleep_for(300ms);
  const auto t0 = Clock::now();
  (void)stream.stop();
  const double took = std::chrono::duration<double>(Clock::now() - t0).count();
  // The init is cut short at once; the stop sequence (streaming off, 9600) then gives up on the
  // silent device after one retry of 100 ms each (a full init could take ~10 s). About 0.3 s on
  // a quiet machine; the bound leaves room for a loaded CI runner (1.08 s seen at load 20) while
  // still telling "cut short" from "waited for the init".
  EXPECT_LT(took, 2.5) << "stop() waited for the init";
  EXPECT_EQ(stream.state(), StreamState::kStopped);
}

TEST_F(LmsSim, InterlacedPartialScansAreMerged) {
  sim::SimOptions o;
  startSim(o);
  auto c = config(500000, {100, 25});  // 4 rotations of 101/100/100/100 beams -> 401
  c.interlaced = true;
  Lms291 lms(c);
  ASSERT_TRUE(lms.start());
  for (int i = 0; i < 10; ++i) {
    auto s = lms.readScan(1000ms);
    ASSERT_TRUE(s) << s.error().message();
    ASSERT_EQ(s->size(), 401u);
    EXPECT_NEAR(s->beamAngle(0) * 180 / M_PI, 40.0, 1e-9);
    EXPECT_NEAR(s->beamAngle(400) * 180 / M_PI, 140.0, 1e-9);
    EXPECT_TRUE(matchesRoom(*s, false));
  }
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, RangeAndRemission) {
  sim::SimOptions o;
  startSim(o);
  auto c = config(500000, {180, 100});
  c.remission = true;
  Lms291 lms(c);
  auto info = lms.start();
  ASSERT_TRUE(info) << info.error().message();
  auto s = lms.readScan(1000ms);
  ASSERT_TRUE(s) << s.error().message();
  ASSERT_EQ(s->remissions.size(), 181u);
  EXPECT_TRUE(matchesRoom(*s, false));
  EXPECT_FLOAT_EQ(s->remissions[90], 300.0f);  // wall straight ahead
  EXPECT_FLOAT_EQ(s->remissions[76], 900.0f);  // the post at atan2(2, 0.5) = 76 deg
  EXPECT_TRUE(lms.stop());
  // 0.5 deg remission scans would not fit a telegram: refused before touching the device.
  auto bad = config(500000, {180, 50});
  bad.remission = true;
  EXPECT_FALSE(bad.validate().empty());
}

TEST_F(LmsSim, StatusWarningsAreSurfacedOnScans) {
  sim::SimOptions o;
  startSim(o);
  Lms291 lms(config(500000, {180, 100}));
  ASSERT_TRUE(lms.start());
  EXPECT_EQ(lms.counters().statusWarnings, 0u);
  sim_->setStatus(0x82);  // warning + pollution
  std::optional<LaserScan> s;
  for (int i = 0; i < 10; ++i) {
    auto r = lms.readScan(1000ms);
    ASSERT_TRUE(r);
    s = *r;
  }
  EXPECT_EQ(s->status, 0x82);
  EXPECT_TRUE(lms.lastStatus().pollution());
  EXPECT_GE(lms.counters().statusWarnings, 5u);
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, LmsFastIsRefusedWithAClearError) {
  sim::SimOptions o;
  o.type = "LMS291;S14";
  startSim(o);
  Lms291 lms(config(38400));
  auto info = lms.start();
  ASSERT_FALSE(info);
  EXPECT_EQ(info.error().code, std::errc::not_supported);
  EXPECT_NE(info.error().message().find("LMS291;S14"), std::string::npos) << info.error().message();
  EXPECT_TRUE(lms.stop());
  EXPECT_EQ(sim_->state().baud, 9600);
}

TEST_F(LmsSim, InterlacedHalfDegreeUnderCorruptionDropsOnlyBrokenGroups) {
  sim::SimOptions o;
  o.seed = 77;
  startSim(o);
  auto c = config(500000, {180, 50});  // 2 partial scans of 181 + 180 beams per full scan
  c.interlaced = true;
  Lms291 lms(c);
  ASSERT_TRUE(lms.start());
  sim::Faults f;
  f.bitFlipRate = 0.001;
  sim_->setFaults(f);
  int scans = 0;
  const auto end = Clock::now() + 3s;
  while (Clock::now() < end) {
    auto s = lms.readScan(500ms);
    if (!s) continue;
    ASSERT_EQ(s->size(), 361u);
    if (sim_->crcBlindScans().empty()) {
      ASSERT_TRUE(matchesRoom(*s, false));
    }
    ++scans;
  }
  sim_->setFaults({});
  const auto k = lms.counters();
  std::printf("interlaced 0.5 deg, 0.1%% flips: %d merged scans, %llu broken groups, %llu damaged partials\n", scans,
              (unsigned long long)k.lostScans, (unsigned long long)sim_->counters().scansDamaged);
  EXPECT_GT(scans, 30);
  EXPECT_GT(k.lostScans, 0u);
  EXPECT_LE(k.lostScans, sim_->counters().scansDamaged);
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, OutputIsPacedAtTheLineRate) {
  // 38400 baud, 361 beams: a 732-byte scan takes 190.6 ms on the line; the device sends a new
  // scan at the first full scan (2 rotations, 26.7 ms) after the line is free: every 8th pair
  // of rotations -> 213.3 ms, 4.69 scans/s (PLY documents ~5 Hz at 38400).
  sim::SimOptions o;
  startSim(o);
  Lms291 lms(config(38400));
  ASSERT_TRUE(lms.start());
  ASSERT_TRUE(lms.readScan(1000ms));
  auto first = lms.readScan(1000ms);
  ASSERT_TRUE(first);
  int n = 0;
  fusedet::Stamp last;
  while (n < 12) {
    auto s = lms.readScan(1000ms);
    ASSERT_TRUE(s);
    last = s->stamp;
    ++n;
  }
  const double periodMs = double(last - first->stamp) * 1e-6 / n;
  std::printf("38400 baud, 361 beams: one scan every %.1f ms (%.2f scans/s)\n", periodMs, 1000.0 / periodMs);
  EXPECT_NEAR(periodMs, 8 * 2 * 1000.0 / 75, 12.0);  // 7 or 9 rotation pairs would be 187 or 240 ms
  EXPECT_TRUE(lms.stop());
}

TEST_F(LmsSim, Termios2PathAt500k) {
  sim::SimOptions o;
  startSim(o);
  auto c = config(500000, {180, 100});
  c.forceTermios2 = true;
  Lms291 lms(c);
  ASSERT_TRUE(lms.start());
  EXPECT_TRUE(lms.link().usedTermios2());
  EXPECT_EQ(sim_->state().hostBaud, 500000);
  EXPECT_TRUE(lms.readScan(1000ms));
  auto stopped = lms.stop();
  EXPECT_TRUE(stopped) << stopped.error().message() << "; link: " << lms.counters().link.timeouts << " timeouts, "
                       << lms.counters().link.retries << " retries, " << lms.counters().link.passedOver << " passed over";
}

// A device that answers late (ACK 250 ms after a request; the host resends after 100 ms) answers
// every copy. The next request with the same reply code must get its own reply, not the late
// answer to a copy of the previous one: variant 100 deg is asked (sent up to three times), then
// 180 deg, and the second reply must report 180 deg.
//
// One run of that scenario with a fresh simulator and driver. Returns why the run says nothing
// (a step met only silence: errc::timed_out), nullopt when it ran to the end; every other error
// and every wrong reply is a test failure here.
std::optional<std::string> LmsSim::lateAnswerRun() {
  const auto silent = [](const char* step, const fusedet::Error& e) -> std::optional<std::string> {
    if (e.code == std::errc::timed_out) return std::string(step) + ": " + e.message();
    ADD_FAILURE() << step << ": " << e.message();
    return std::nullopt;
  };
  startSim(sim::SimOptions{});
  Lms291 lms(config(500000, {180, 100}));
  auto started = lms.start();
  if (!started) return silent("start()", started.error());
  RequestOptions ro;
  ro.ackTimeout = 100ms;
  ro.replyTimeout = 1000ms;
  ro.retries = 10;  // copies every ~100 ms: the 250 ms ACK arrives during the third
  const std::uint8_t monitoring[] = {0x25};
  auto mode = lms.link().request(static_cast<std::uint8_t>(Command::kSwitchMode), monitoring, ro);  // no scans between
  if (!mode) return silent("monitoring mode", mode.error());
  sim::Faults late;
  late.ackDelay = 250ms;
  sim_->setFaults(late);
  const auto before = lms.counters().link;
  auto first = lms.link().request(static_cast<std::uint8_t>(Command::kSetVariant), variantPayload({100, 100}), ro);
  auto second = lms.link().request(static_cast<std::uint8_t>(Command::kSetVariant), variantPayload({180, 100}), ro);
  sim_->setFaults({});
  if (!first) return silent("first request", first.error());
  if (!second) return silent("second request", second.error());
  EXPECT_EQ(first->data.size(), 5u);
  EXPECT_EQ(second->data.size(), 5u);
  if (first->data.size() != 5u || second->data.size() != 5u) return std::nullopt;
  EXPECT_EQ(u16(first->data, 1), 100);
  EXPECT_EQ(u16(second->data, 1), 180) << "the second request took a late answer to the first";
  const auto k = lms.counters().link;
  std::printf("late device: %llu copies sent again, %llu late answers taken, %llu passed over; simulator: %llu requests\n",
              (unsigned long long)(k.retries - before.retries), (unsigned long long)(k.lateAnswers - before.lateAnswers),
              (unsigned long long)(k.passedOver - before.passedOver), (unsigned long long)sim_->counters().requests);
  EXPECT_LE(k.lateAnswers - before.lateAnswers, k.retries - before.retries);
  auto stopped = lms.stop();
  if (!stopped) return silent("stop()", stopped.error());
  EXPECT_EQ(sim_->state().baud, 9600);
  return std::nullopt;
}

// Under load, the kernel of the shared test machine left the pty's flip-buffer work
// (flush_to_ldisc) unscheduled for seconds: the driver's and the simulator's threads both sat in
// poll() in D state (__flush_work from n_tty_poll) and the simulator's trace shows that the host's
// bytes never reached it (2026-11-30, /work/coord/notes-flaky.md). A run in which a step met only
// silence says nothing about late answers, so it is run again with a fresh simulator and driver,
// at most 5 runs within 45 s (the count is printed). A wrong reply, any other error, or a run that
// ends wrong fails at once; the assertions of a run are those above, unchanged.
TEST_F(LmsSim, LateAnswersToResentCopiesAreNotTakenForTheNextReply) {
  const auto t0 = std::chrono::steady_clock::now();
  std::vector<std::string> silences;
  for (;;) {
    const std::optional<std::string> silence = lateAnswerRun();
    if (HasFailure()) return;
    if (!silence) break;
    silences.push_back(*silence);
    std::printf("run %zu met only silence (%s); again with a fresh simulator\n", silences.size(), silence->c_str());
    if (silences.size() >= 5 || std::chrono::steady_clock::now() - t0 > 45s)
      FAIL() << silences.size() << " runs met only silence; the last: " << silences.back();
  }
  std::printf("runs: %zu (%zu met only silence)\n", silences.size() + 1, silences.size());
}

TEST_F(LmsSim, BytesAtTheWrongSpeedAreIgnoredAndScanStampsAccountForLineTime) {
  sim::SimOptions o;
  startSim(o);
  // A host at 38400 talking to a device at 9600: nothing is understood.
  auto port = fusedet::drivers::SerialPort::open(link_, 38400);
  ASSERT_TRUE(port);
  const auto req = encodeRequest(0x31);
  ASSERT_TRUE(port->write(req, 1s));
  std::uint8_t buf[64];
  auto n = port->read(buf, 300ms);
  ASSERT_TRUE(n);
  EXPECT_EQ(*n, 0u);
  EXPECT_EQ(sim_->counters().ignoredBytes, req.size());
  port->close();

  // Stamp = reception minus line time: at 38400 baud a 372-byte scan takes 96.9 ms, so the
  // stamp lies at least that far before the moment readScan returned it.
  Lms291 lms(config(38400, {180, 100}));
  ASSERT_TRUE(lms.start());
  for (int i = 0; i < 3; ++i) {
    auto s = lms.readScan(2000ms);
    ASSERT_TRUE(s);
    const double ageMs = double(fusedet::Stamp::now() - s->stamp) * 1e-6;
    EXPECT_GE(ageMs, 372 * 10.0 / 38400 * 1000);
    EXPECT_LT(ageMs, 372 * 10.0 / 38400 * 1000 + 300);  // loose: the test thread may be descheduled
  }
  EXPECT_TRUE(lms.stop());
}

}  // namespace
