// SPDX-License-Identifier: Apache-2.0
// Sweep assembly on synthetic geometry: a nodding scanner in front of a wall at a known distance,
// with ranges ray-cast here (own rotation matrix, own ray-plane intersection).

#include "fusedet/fusion/sweep_assembler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <optional>

using namespace fusedet;
using namespace fusedet::fusion;
using drivers::LaserScan;
using drivers::TiltSample;

namespace {
constexpr double kPi = 3.14159265358979323846;
constexpr double kWallX = 4.0;         // wall: the plane x = 4 m of the base frame
constexpr double kOffsetZ = 0.05;      // scanner 5 cm above the tilt axis
constexpr std::int64_t kScanNs = 13'333'333;  // 1/75 s per mirror turn
constexpr std::int64_t kT0 = 1'000'000'000;

// Rotation about +y by t (right hand): x' = x cos t + z sin t, z' = -x sin t + z cos t.
void rotY(double t, double& x, double& z) {
  const double nx = x * std::cos(t) + z * std::sin(t), nz = -x * std::sin(t) + z * std::cos(t);
  x = nx;
  z = nz;
}

struct Ray {
  double ox, oy, oz, dx, dy, dz;
};
// Beam at angle a (0 right, 90 deg ahead) with the scanner tilted by t.
Ray beamRay(double a, double t) {
  Ray r{0, 0, kOffsetZ, std::sin(a), -std::cos(a), 0};
  rotY(t, r.ox, r.oz);
  rotY(t, r.dx, r.dz);
  return r;
}

// LMS-like scan: 181 beams over 180 deg (100 deg here to keep every beam on the wall).
// interlaced: like the LMS's 0.5/0.25 deg modes, all beams carry the scan's stamp (beamDuration 0).
LaserScan wallScan(std::int64_t stampNs, const std::function<double(std::int64_t)>& tiltOf, std::uint64_t seq,
                   bool interlaced = false) {
  LaserScan s;
  s.stamp = Stamp{stampNs};
  s.sequence = seq;
  s.startAngle = 40 * kPi / 180;
  s.angleStep = 0.5 * kPi / 180;
  s.beamDuration = interlaced ? 0.0 : (kScanNs / 2) * 1e-9 / 201;  // half a mirror turn covers the field of view
  for (int i = 0; i < 201; ++i) {
    const Ray r = beamRay(s.beamAngle(static_cast<std::size_t>(i)), tiltOf(s.beamStamp(static_cast<std::size_t>(i)).ns));
    s.ranges.push_back(static_cast<float>((kWallX - r.ox) / r.dx));
    s.remissions.push_back(static_cast<float>(i));
  }
  return s;
}

// Triangle profile: from -20 deg up to +20 deg at 40 deg/s (1 s), then down again.
double triangle(std::int64_t ns) {
  const double t = static_cast<double>(ns - kT0) * 1e-9;
  const double deg = t <= 1.0 ? -20 + 40 * t : 20 - 40 * (t - 1.0);
  return deg * kPi / 180;
}

SweepConfig wallConfig() {
  SweepConfig c;
  c.tiltAxisOffset = Eigen::Vector3d(0, 0, kOffsetZ);
  c.remissionFullScale = 200;
  return c;
}

// Feeds tilt samples at 100 Hz from 20 ms before kT0 to 30 ms after `to` (so the last scan is
// covered), and scans every 1/75 s from kT0 to `to`, in time order.
void feed(SweepAssembler& a, std::int64_t to, const std::function<double(std::int64_t)>& tiltOf,
          const std::function<bool(std::int64_t)>& tiltPresent = [](std::int64_t) { return true; },
          bool interlaced = false) {
  std::int64_t nextTilt = kT0 - 20'000'000, nextScan = kT0;
  std::uint64_t seq = 0;
  while (nextScan < to || nextTilt < to + 30'000'000) {
    if (nextTilt <= nextScan || nextScan >= to) {
      if (tiltPresent(nextTilt)) a.addTilt(TiltSample{Stamp{nextTilt}, tiltOf(nextTilt), 0});
      nextTilt += 10'000'000;
    } else {
      a.addScan(wallScan(nextScan, tiltOf, seq++, interlaced));
      nextScan += kScanNs;
    }
  }
}
}  // namespace

TEST(SweepAssembler, PointsOfAWallLieOnTheWallWhereTheBeamsHitIt) {
  SweepAssembler a(wallConfig());
  feed(a, kT0 + 900'000'000, triangle);  // rising only
  a.flush();
  const auto sweeps = a.takeSweeps();
  ASSERT_EQ(sweeps.size(), 1u);
  const Sweep& s = sweeps[0];
  EXPECT_EQ(a.stats().scansDroppedNoTilt, 0u);
  EXPECT_EQ(s.size(), a.stats().scansUsed * 201);
  double worst = 0;
  for (std::size_t k = 0; k < s.size(); ++k) {
    const SweepPoint& p = s.points[k];
    // Expected point: the ray of beam i at the tilt of the beam's own time, cut with the wall.
    const std::size_t scanIndex = k / 201, i = k % 201;
    const LaserScan scan = wallScan(kT0 + static_cast<std::int64_t>(scanIndex) * kScanNs, triangle, 0);
    const Ray r = beamRay(scan.beamAngle(i), triangle(scan.beamStamp(i).ns));
    const double lambda = (kWallX - r.ox) / r.dx;
    worst = std::max({worst, std::abs(p.x - (r.ox + lambda * r.dx)), std::abs(p.y - (r.oy + lambda * r.dy)),
                      std::abs(p.z - (r.oz + lambda * r.dz))});
    EXPECT_EQ(p.stampNs, scan.beamStamp(i).ns);
    EXPECT_FLOAT_EQ(p.remission, static_cast<float>(i) / 200.f);
  }
  // Linear tilt profile: interpolation is exact, only float storage of ranges/points remains.
  EXPECT_LT(worst, 2e-5 * 10);
  EXPECT_EQ(s.start, Stamp{kT0});
  EXPECT_EQ(s.frame, Sweep::Frame::kRobot);
}

TEST(SweepAssembler, UsesEachBeamsOwnTimeNotTheScanStamp) {
  // Fast nod: 400 deg/s, so the 6.7 ms a scan takes tilts the beams by 2.7 deg.
  const auto fast = [](std::int64_t ns) { return (-20 + 400 * static_cast<double>(ns - kT0) * 1e-9) * kPi / 180; };
  SweepAssembler a(wallConfig());
  feed(a, kT0 + 90'000'000, fast);
  a.flush();
  const auto sweeps = a.takeSweeps();
  ASSERT_EQ(sweeps.size(), 1u);
  const SweepPoint& last = sweeps[0].points[200];  // last beam of the first scan, straight-ish ahead
  const LaserScan scan = wallScan(kT0, fast, 0);
  const Ray r = beamRay(scan.beamAngle(200), fast(scan.beamStamp(200).ns));
  const double lambda = (kWallX - r.ox) / r.dx;
  EXPECT_NEAR(last.z, r.oz + lambda * r.dz, 1e-4);
  const Ray atScanStart = beamRay(scan.beamAngle(200), fast(kT0));
  EXPECT_GT(std::abs(last.z - (atScanStart.oz + lambda * atScanStart.dz)), 0.05);  // would be wrong
}

TEST(SweepAssembler, SplitsAtTiltReversals) {
  SweepAssembler a(wallConfig());
  feed(a, kT0 + 1'980'000'000, triangle);
  a.flush();
  const auto sweeps = a.takeSweeps();
  ASSERT_EQ(sweeps.size(), 2u);
  // The peak is at kT0 + 1 s: the first sweep ends, the second starts within one scan of it.
  EXPECT_NEAR(static_cast<double>(sweeps[0].end.ns - kT0) * 1e-9, 1.0, 2 * kScanNs * 1e-9);
  EXPECT_NEAR(static_cast<double>(sweeps[1].start.ns - kT0) * 1e-9, 1.0, 2 * kScanNs * 1e-9);
  EXPECT_EQ(sweeps[0].id + 1, sweeps[1].id);
  EXPECT_EQ(a.stats().sweeps, 2u);
  EXPECT_EQ(a.stats().points, sweeps[0].size() + sweeps[1].size());
  // Each sweep covers (nearly) the full nodding range: z on the wall spans both tilt limits.
  for (const Sweep& s : sweeps) {
    float lo = 1e9f, hi = -1e9f;
    for (const SweepPoint& p : s.points) {
      lo = std::min(lo, p.z);
      hi = std::max(hi, p.z);
    }
    EXPECT_LT(lo, -1.3f);  // 4 m * tan(20 deg) = 1.46 m, minus the start/end scans
    EXPECT_GT(hi, 1.3f);
  }
}

TEST(SweepAssembler, SplitsInterlacedScansAtTiltReversals) {
  // No tilt change inside a scan: the direction must come from one scan to the next.
  SweepAssembler a(wallConfig());
  feed(a, kT0 + 1'980'000'000, triangle, [](std::int64_t) { return true; }, true);
  a.flush();
  const auto sweeps = a.takeSweeps();
  ASSERT_EQ(sweeps.size(), 2u);
  EXPECT_NEAR(static_cast<double>(sweeps[0].end.ns - kT0) * 1e-9, 1.0, 2 * kScanNs * 1e-9);
  EXPECT_NEAR(static_cast<double>(sweeps[1].start.ns - kT0) * 1e-9, 1.0, 2 * kScanNs * 1e-9);
  EXPECT_EQ(a.stats().scansUsed, a.stats().scans);
}

TEST(SweepAssembler, DropsAndCountsScansWithoutTiltNeverExtrapolates) {
  SweepAssembler a(wallConfig());
  // Tilt samples missing between 300 ms and 500 ms: scans there cannot be interpolated.
  const auto present = [](std::int64_t ns) { return ns < kT0 + 300'000'000 || ns > kT0 + 500'000'000; };
  feed(a, kT0 + 800'000'000, triangle, present);
  // Tilt stops at 800 ms; scans after that wait, then are dropped at the end of the stream.
  for (int k = 0; k < 5; ++k) a.addScan(wallScan(kT0 + 900'000'000 + k * kScanNs, triangle, 1000));
  a.flush();
  const SweepStats& st = a.stats();
  // Samples at 290 ms and then 510 ms: a beam between them has no sample within 50 ms on both
  // sides, so every scan with a beam in (290, 510) ms is dropped, plus the 5 late scans.
  std::uint64_t expected = 5;
  const std::int64_t lastBeam = wallScan(kT0, triangle, 0).beamStamp(200) - Stamp{kT0};
  for (std::int64_t start = kT0; start < kT0 + 800'000'000; start += kScanNs)
    if (start + lastBeam > kT0 + 290'000'000 && start < kT0 + 510'000'000) ++expected;
  EXPECT_EQ(st.scansDroppedNoTilt, expected);
  EXPECT_EQ(st.scansUsed + st.scansDroppedNoTilt, st.scans);
  for (const Sweep& s : a.takeSweeps())
    for (const SweepPoint& p : s.points) {
      EXPECT_FALSE(p.stampNs > kT0 + 290'000'000 && p.stampNs < kT0 + 510'000'000);
      EXPECT_LE(p.stampNs, kT0 + 830'000'000);  // nothing beyond the last tilt sample
    }
}

TEST(SweepAssembler, InterpolatesTiltAndRefusesOutsideTheWindow) {
  SweepAssembler a(wallConfig());
  a.addTilt(TiltSample{Stamp{1'000'000'000}, 0.1, 0});
  a.addTilt(TiltSample{Stamp{1'040'000'000}, 0.3, 0});
  a.addTilt(TiltSample{Stamp{1'030'000'000}, 9.0, 0});  // out of order: ignored
  double angle = 0;
  ASSERT_TRUE(a.tiltAt(Stamp{1'010'000'000}, angle));
  EXPECT_NEAR(angle, 0.15, 1e-12);
  ASSERT_TRUE(a.tiltAt(Stamp{1'040'000'000}, angle));
  EXPECT_NEAR(angle, 0.3, 1e-12);
  EXPECT_FALSE(a.tiltAt(Stamp{1'041'000'000}, angle));  // after the last sample: no extrapolation
  EXPECT_FALSE(a.tiltAt(Stamp{999'000'000}, angle));    // before the first
  a.addTilt(TiltSample{Stamp{1'200'000'000}, 0.5, 0});
  EXPECT_FALSE(a.tiltAt(Stamp{1'100'000'000}, angle));  // 60 ms from both neighbours > 50 ms window
  EXPECT_EQ(a.stats().tiltOutOfOrder, 1u);
}

TEST(SweepAssembler, RejectsInvalidReturnsAndBadConfig) {
  SweepAssembler a(wallConfig());
  a.addTilt(TiltSample{Stamp{kT0 - 10'000'000}, 0, 0});
  a.addTilt(TiltSample{Stamp{kT0 + 20'000'000}, 0, 0});
  LaserScan s;
  s.stamp = Stamp{kT0};
  s.angleStep = 0.01;
  s.beamDuration = 1e-5;
  s.ranges = {0.f, NAN, 2.f, 100.f, 0.01f};
  a.addScan(s);
  a.flush();
  const auto sweeps = a.takeSweeps();
  ASSERT_EQ(sweeps.size(), 1u);
  ASSERT_EQ(sweeps[0].size(), 1u);  // only the 2 m return
  EXPECT_NEAR(sweeps[0].points[0].y, -2.0 * std::cos(0.02), 1e-6);
  EXPECT_EQ(sweeps[0].points[0].remission, 0.f);  // no remissions in the scan
  SweepConfig bad;
  bad.tiltAxis = Eigen::Vector3d::Zero();
  EXPECT_THROW(SweepAssembler{bad}, std::invalid_argument);
}

// When a sweep closes (SweepConfig::closeOnTilt): messages fed in the order the daemon receives
// them - a tilt sample at its stamp (CAN frames arrive at once), a scan when its telegram is in,
// 8 ms after its last beam (500 kbaud) - and, for every sweep, the message that emitted it.
namespace {
constexpr std::int64_t kTelegramNs = 8'000'000;
const std::int64_t kScanSpanNs = wallScan(kT0, triangle, 0).beamStamp(200) - Stamp{kT0};  // 6.6 ms

std::int64_t scanStart(int n) { return kT0 + n * kScanNs; }

// Up from -20 deg at 40 deg/s to a peak at `peakNs`, then down at 40 deg/s.
std::function<double(std::int64_t)> peakAt(std::int64_t peakNs) {
  return [peakNs](std::int64_t ns) { return (20 - 40 * std::abs(static_cast<double>(ns - peakNs)) * 1e-9) * kPi / 180; };
}

struct Emitted {
  enum class By { kTilt, kScan, kFlush } by;
  std::int64_t stamp;  // of the tilt sample or the scan that emitted it
  Sweep sweep;
};

struct Stream {
  std::function<double(std::int64_t)> tilt;
  std::int64_t tiltPeriodNs = 10'000'000;
  std::int64_t tiltPhaseNs = 0;  // samples at kT0 + phase + k * period
  std::int64_t to = kT0 + 1'500'000'000;  // scans start before this
  bool interlaced = false;
  std::function<bool(std::int64_t)> tiltPresent = [](std::int64_t) { return true; };
};

std::vector<Emitted> run(const Stream& in, bool closeOnTilt, SweepStats* stats = nullptr) {
  struct Message {
    std::int64_t arrival;
    bool scan;
    std::int64_t stamp;
  };
  std::vector<Message> messages;
  for (std::int64_t t = kT0 - 20'000'000 + in.tiltPhaseNs; t < in.to + 30'000'000; t += in.tiltPeriodNs)
    if (in.tiltPresent(t)) messages.push_back({t, false, t});
  for (int n = 0; scanStart(n) < in.to; ++n)
    messages.push_back({scanStart(n) + (in.interlaced ? 0 : kScanSpanNs) + kTelegramNs, true, scanStart(n)});
  std::stable_sort(messages.begin(), messages.end(), [](const Message& a, const Message& b) { return a.arrival < b.arrival; });
  SweepConfig config = wallConfig();
  config.closeOnTilt = closeOnTilt;
  SweepAssembler a(config);
  std::vector<Emitted> out;
  std::uint64_t seq = 0;
  for (const Message& m : messages) {
    if (m.scan)
      a.addScan(wallScan(m.stamp, in.tilt, seq++, in.interlaced));
    else
      a.addTilt(TiltSample{Stamp{m.stamp}, in.tilt(m.stamp), 0});
    for (Sweep& s : a.takeSweeps()) out.push_back({m.scan ? Emitted::By::kScan : Emitted::By::kTilt, m.stamp, std::move(s)});
  }
  a.flush();
  for (Sweep& s : a.takeSweeps()) out.push_back({Emitted::By::kFlush, 0, std::move(s)});
  if (stats) *stats = a.stats();
  return out;
}

// Same scans in the same sweeps, point for point.
void expectSameSweeps(const std::vector<Emitted>& a, const std::vector<Emitted>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k) {
    const Sweep &x = a[k].sweep, &y = b[k].sweep;
    EXPECT_EQ(x.id, y.id);
    EXPECT_EQ(x.start, y.start);
    EXPECT_EQ(x.end, y.end);
    ASSERT_EQ(x.size(), y.size()) << "sweep " << k;
    for (std::size_t i = 0; i < x.size(); ++i) {
      EXPECT_EQ(x.points[i].stampNs, y.points[i].stampNs);
      EXPECT_EQ(x.points[i].z, y.points[i].z);
    }
  }
}

// The stream with closeOnTilt (early) and without (late): the same sweeps either way.
struct BothRules {
  std::vector<Emitted> early, late;
  SweepStats stats;  // of early
};
BothRules runBoth(const Stream& in) {
  BothRules r;
  r.early = run(in, true, &r.stats);
  r.late = run(in, false);
  expectSameSweeps(r.early, r.late);
  return r;
}
}  // namespace

TEST(SweepAssemblerClose, ClosesWhenTheTiltSampleAfterThePeakArrivesNotOnTheNextScan) {
  // Peak 1 ms after scan 74's last beam (993.3 ms): scans 0-74 rise over their whole span, scan
  // 75 (from 1000 ms) falls. 100 Hz samples at 5, 15, ... ms: the one at 995 ms is still above
  // the tilt at scan 74's last beam, the one at 1005 ms is the first below it. Scan 75 reaches
  // the assembler at 1000 + 6.6 + 8 ms.
  Stream in;
  in.tilt = peakAt(scanStart(74) + kScanSpanNs + 1'000'000);
  in.tiltPhaseNs = 5'000'000;
  const auto [early, late, stats] = runBoth(in);
  ASSERT_EQ(early.size(), 2u);
  EXPECT_EQ(early[0].by, Emitted::By::kTilt);
  EXPECT_EQ(early[0].stamp, kT0 + 1'005'000'000);
  EXPECT_EQ(early[0].sweep.size(), 75u * 201);  // scans 0-74, every beam on the wall
  EXPECT_EQ(early[0].sweep.end, Stamp{scanStart(74) + kScanSpanNs});
  EXPECT_EQ(early[1].sweep.start, Stamp{scanStart(75)});
  // Without closeOnTilt scan 75 closes it, once it is in and a sample covers its last beam.
  EXPECT_EQ(late[0].by, Emitted::By::kTilt);
  EXPECT_EQ(late[0].stamp, kT0 + 1'015'000'000);
  EXPECT_EQ(stats.sweepsClosedOnTilt, 1u);
  EXPECT_EQ(stats.scansUsed, stats.scans);  // none dropped, every used scan in one sweep
  EXPECT_EQ(stats.points, early[0].sweep.size() + early[1].sweep.size());
}

TEST(SweepAssemblerClose, AScanThatStraddlesThePeakGoesWhereItsNetTiltChangeSays) {
  // 1 kHz tilt samples, so the interpolated tilt is the profile. Scan 75 spans 0-6.6 ms after
  // its stamp; the peak inside it decides by the scan's net change.
  for (const std::int64_t peakInScan : {2'000'000, 5'000'000}) {
    SCOPED_TRACE(peakInScan);
    Stream in;
    in.tilt = peakAt(scanStart(75) + peakInScan);
    in.tiltPeriodNs = 1'000'000;
    const bool rises = peakInScan > kScanSpanNs - peakInScan;  // longer up than down
    const auto [early, late, stats] = runBoth(in);
    ASSERT_EQ(early.size(), 2u);
    const int lastScan = rises ? 75 : 74;
    EXPECT_EQ(early[0].sweep.size(), static_cast<std::size_t>(lastScan + 1) * 201);
    EXPECT_EQ(early[1].sweep.start, Stamp{scanStart(lastScan + 1)});
    if (rises) {
      // Up 5 ms, down 1.6 ms: no sample can tell before scan 75 is in; it joins the sweep and
      // closes it - the samples by then show the descent at scan 76's start.
      EXPECT_EQ(early[0].by, Emitted::By::kScan);
      EXPECT_EQ(early[0].stamp, scanStart(75));
    } else {
      // Up 2 ms, down 4.6 ms: the first sample after the peak (1003 ms) shows scan 75 (and any
      // later scan) falling over its span, 11.6 ms before scan 75 is in.
      EXPECT_EQ(early[0].by, Emitted::By::kTilt);
      EXPECT_EQ(early[0].stamp, kT0 + 1'003'000'000);
    }
    // Without closeOnTilt the first falling scan closes it: 75 or 76, once in.
    EXPECT_EQ(late[0].by, Emitted::By::kScan);
    EXPECT_EQ(late[0].stamp, scanStart(lastScan + 1));
    EXPECT_EQ(stats.sweepsClosedOnTilt, 1u);
  }
}

TEST(SweepAssemblerClose, InterlacedScansCloseOnTheTiltSampleToo) {
  // All beams at the scan's stamp: a scan's direction is its tilt against the previous scan's.
  // Peak on the 100 Hz grid at 1000 ms = scan 75's stamp (interpolation exact): scan 75 is
  // higher than scan 74 (rising stroke), scan 76 lower. The sample at 1010 ms is the first
  // below scan 75's tilt; scan 76 (1013.3 ms) arrives at 1021.3 ms.
  Stream in;
  in.interlaced = true;
  in.tilt = peakAt(kT0 + 1'000'000'000);
  const auto [early, late, stats] = runBoth(in);
  ASSERT_EQ(early.size(), 2u);
  EXPECT_EQ(early[0].by, Emitted::By::kTilt);
  EXPECT_EQ(early[0].stamp, kT0 + 1'010'000'000);
  EXPECT_EQ(early[0].sweep.size(), 76u * 201);
  EXPECT_EQ(late[0].by, Emitted::By::kScan);
  EXPECT_EQ(late[0].stamp, scanStart(76));
  EXPECT_EQ(stats.sweepsClosedOnTilt, 1u);
}

TEST(SweepAssemblerClose, WithoutTiltSamplesAfterTheSweepItClosesAsBefore) {
  const auto peak = scanStart(74) + kScanSpanNs + 1'000'000;
  {
    // The tilt stream stops at 990 ms, before scan 74's last beam: nothing proves a reversal,
    // later scans are dropped without tilt, and only flush() closes the sweep.
    Stream in;
    in.tilt = peakAt(peak);
    in.tiltPresent = [](std::int64_t t) { return t <= kT0 + 990'000'000; };
    const auto [early, late, stats] = runBoth(in);
    ASSERT_EQ(early.size(), 1u);
    EXPECT_EQ(early[0].by, Emitted::By::kFlush);
    EXPECT_EQ(early[0].sweep.size(), 74u * 201);  // scans 0-73: 74 ends after the last sample
    EXPECT_EQ(stats.sweepsClosedOnTilt, 0u);
    EXPECT_EQ(stats.scansUsed + stats.scansDroppedNoTilt, stats.scans);
  }
  {
    // No samples from 990 to 1030 ms (within the 50 ms window): scans 74 and 75 wait for the
    // sample at 1030 ms, which then decides both - scan 75 closes the sweep, as without closeOnTilt.
    Stream in;
    in.tilt = peakAt(peak);
    in.tiltPresent = [](std::int64_t t) { return t <= kT0 + 990'000'000 || t >= kT0 + 1'030'000'000; };
    const auto [early, late, stats] = runBoth(in);
    ASSERT_EQ(early.size(), 2u);
    EXPECT_EQ(early[0].by, Emitted::By::kTilt);
    EXPECT_EQ(early[0].stamp, kT0 + 1'030'000'000);
    EXPECT_EQ(late[0].stamp, kT0 + 1'030'000'000);
    EXPECT_EQ(stats.sweepsClosedOnTilt, 0u);
  }
}

// Issue 37: a parked (or faulted) tilt motor while the laser scans. Every scan is at rest, so it
// joined the open sweep, which never closed: its points grew without bound (a minute here is
// 900k points; hours on a robot). Now no sweep - emitted or open - spans more than maxSweepS,
// the over-long ones are cut and counted, and tiltStillS says how long the tilt has stood still.
TEST(SweepAssemblerBounds, AParkedTiltNeverGrowsASweepPastItsLimit) {
  SweepConfig config = wallConfig();
  config.maxSweepS = 4.0;
  SweepAssembler a(config);
  const auto parkedAfterOneNod = [](std::int64_t ns) { return triangle(std::min<std::int64_t>(ns, kT0 + 2'000'000'000)); };
  const std::int64_t end = kT0 + 60'000'000'000;  // a minute of scans at 75 Hz
  std::size_t maxOpen = 0;
  std::int64_t nextTilt = kT0 - 20'000'000, nextScan = kT0;
  std::uint64_t seq = 0;
  std::vector<Sweep> sweeps;
  while (nextScan < end) {
    if (nextTilt <= nextScan) {
      a.addTilt(TiltSample{Stamp{nextTilt}, parkedAfterOneNod(nextTilt), 0});
      nextTilt += 10'000'000;
    } else {
      a.addScan(wallScan(nextScan, parkedAfterOneNod, seq++));
      nextScan += kScanNs;
    }
    maxOpen = std::max(maxOpen, a.openPoints());
    for (Sweep& s : a.takeSweeps()) sweeps.push_back(std::move(s));
  }
  const SweepStats stats = a.stats();
  a.flush();
  for (Sweep& s : a.takeSweeps()) sweeps.push_back(std::move(s));
  ASSERT_FALSE(sweeps.empty());
  for (const Sweep& s : sweeps) EXPECT_LE((s.end - s.start) * 1e-9, config.maxSweepS + 0.02) << "sweep " << s.id;
  // 4 s of scans: 300 scans of 201 points.
  EXPECT_LE(maxOpen, static_cast<std::size_t>(config.maxSweepS * 75 + 2) * 201);
  // Parked from 2 s on: (60 - 2 - the first cut's partial) / 4 s cuts.
  EXPECT_GE(stats.sweepsCut, 13u);
  EXPECT_LE(stats.sweepsCut, 15u);
  EXPECT_NEAR(stats.tiltStillS, 58.0, 0.1);
}

TEST(SweepAssemblerBounds, TheOpenSweepIsCutAtMaxSweepPoints) {
  SweepConfig config = wallConfig();
  config.maxSweepPoints = 201 * 10;
  SweepAssembler a(config);
  feed(a, kT0 + 1'000'000'000, [](std::int64_t) { return 0.1; });
  // 75 scans at rest: cut after every 10 scans.
  EXPECT_EQ(a.stats().sweepsCut, 7u);
  EXPECT_LE(a.openPoints(), config.maxSweepPoints);
}

// The tilt history was trimmed only relative to the newest scan: with the laser silent it grew
// with every sample. Now samples older than maxSweepS before the newest one are forgotten.
TEST(SweepAssemblerBounds, ASilentLaserDoesNotGrowTheTiltHistory) {
  SweepConfig config = wallConfig();
  config.maxSweepS = 2.0;
  SweepAssembler a(config);
  for (std::int64_t t = kT0; t < kT0 + 600'000'000'000; t += 10'000'000)  // 10 min at 100 Hz
    a.addTilt(TiltSample{Stamp{t}, triangle(kT0 + (t - kT0) % 2'000'000'000), 0});
  EXPECT_LE(a.tiltSamplesKept(), 202u);
  double angle = 0;
  EXPECT_FALSE(a.tiltAt(Stamp{kT0 + 1'000'000'000}, angle));           // long forgotten
  EXPECT_TRUE(a.tiltAt(Stamp{kT0 + 600'000'000'000 - 500'000'000}, angle));  // recent: kept
  EXPECT_EQ(a.stats().tiltSamples, 60'000u);
}

namespace {
// Four seconds of nodding (a reversal every second), tilt at 100 Hz and scans at 75 Hz in time
// order; `extra` adds one more tilt sample when the stream reaches its arrival time.
struct ClockRun {
  std::vector<Sweep> sweeps;
  SweepStats stats;
};
ClockRun nodWithExtraSample(std::optional<std::pair<std::int64_t, TiltSample>> extra) {
  const auto nod = [](std::int64_t ns) { return triangle(kT0 + (ns - kT0) % 2'000'000'000); };
  SweepAssembler a(wallConfig());
  ClockRun out;
  std::int64_t nextTilt = kT0 - 20'000'000, nextScan = kT0;
  const std::int64_t end = kT0 + 4'000'000'000;
  std::uint64_t seq = 0;
  while (nextScan < end) {
    if (extra && extra->first <= std::min(nextTilt, nextScan)) {
      a.addTilt(extra->second);
      extra.reset();
    } else if (nextTilt <= nextScan) {
      a.addTilt(TiltSample{Stamp{nextTilt}, nod(nextTilt), 0});
      nextTilt += 10'000'000;
    } else {
      a.addScan(wallScan(nextScan, nod, seq++));
      nextScan += kScanNs;
    }
    for (Sweep& s : a.takeSweeps()) out.sweeps.push_back(std::move(s));
  }
  a.flush();
  for (Sweep& s : a.takeSweeps()) out.sweeps.push_back(std::move(s));
  out.stats = a.stats();
  return out;
}
}  // namespace

// Issue 37, clock jumps: SocketCAN's CLOCK_REALTIME stamps moved to the monotonic clock put the
// frames received around a wall-clock step off by the step. One tilt sample stamped an hour
// ahead made every later sample "out of order": no sweep for the rest of the run (an hour). Now
// three samples in order among themselves restart the history: 30 ms of tilt lost at 100 Hz.
TEST(SweepAssemblerClock, ATiltSampleStampedAnHourAheadCostsThreeSamplesNotAnHour) {
  const ClockRun clean = nodWithExtraSample(std::nullopt);
  ASSERT_EQ(clean.sweeps.size(), 4u);
  const std::int64_t at = kT0 + 1'500'000'000;  // mid-sweep, rising... falling after the 1 s peak
  const ClockRun stepped = nodWithExtraSample(std::make_pair(at, TiltSample{Stamp{at + 3'600'000'000'000}, 0.1, 0}));
  EXPECT_EQ(stepped.stats.tiltClockSteps, 1u);
  // The sweep the step fell into loses the scans of those three samples (or is cut short); the
  // ones after it are exactly those of the clean run.
  ASSERT_GE(stepped.sweeps.size(), 3u);
  const std::uint64_t lostScans = stepped.stats.scansDroppedNoTilt - clean.stats.scansDroppedNoTilt;
  EXPECT_GE(lostScans, 1u);
  EXPECT_LE(lostScans, 4u) << "three 10 ms samples span at most four 13.3 ms scans";
  for (std::size_t k = 1; k <= 2; ++k) {
    const Sweep& x = clean.sweeps[clean.sweeps.size() - k];
    const Sweep& y = stepped.sweeps[stepped.sweeps.size() - k];
    EXPECT_EQ(x.start, y.start);
    EXPECT_EQ(x.end, y.end);
    EXPECT_EQ(x.points.size(), y.points.size());
  }
  std::printf("clock step +1 h: %ju scans without tilt (%.1f ms of 75 Hz scans), %zu sweeps (clean run %zu)\n",
              static_cast<std::uintmax_t>(lostScans), static_cast<double>(lostScans) * kScanNs * 1e-6,
              stepped.sweeps.size(), clean.sweeps.size());
}

// A sample stamped an hour behind (a step the other way) is ignored like any out-of-order one.
TEST(SweepAssemblerClock, ATiltSampleStampedAnHourBehindIsIgnored) {
  const ClockRun clean = nodWithExtraSample(std::nullopt);
  const std::int64_t at = kT0 + 1'500'000'000;
  const ClockRun stepped = nodWithExtraSample(std::make_pair(at, TiltSample{Stamp{at - 3'600'000'000'000}, 0.1, 0}));
  EXPECT_EQ(stepped.stats.tiltClockSteps, 0u);
  EXPECT_EQ(stepped.stats.tiltOutOfOrder, clean.stats.tiltOutOfOrder + 1);
  ASSERT_EQ(stepped.sweeps.size(), clean.sweeps.size());
  for (std::size_t k = 0; k < clean.sweeps.size(); ++k) {
    EXPECT_EQ(stepped.sweeps[k].start, clean.sweeps[k].start);
    EXPECT_EQ(stepped.sweeps[k].points.size(), clean.sweeps[k].points.size());
  }
}
