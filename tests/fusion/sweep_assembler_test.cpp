// Sweep assembly on synthetic geometry: a nodding scanner in front of a wall at a known distance,
// with ranges ray-cast here (own rotation matrix, own ray-plane intersection).

#include "fusedet/fusion/sweep_assembler.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>

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
