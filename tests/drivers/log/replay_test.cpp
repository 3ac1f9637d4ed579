// SPDX-License-Identifier: Apache-2.0
// Replay: a log recorded from known telegrams, CAN frames and camera buffers comes back through
// the live decoders with the values and stamps that went in; pacing, determinism, stop, and a
// cut log replaying up to its last complete chunk.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <thread>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/telegram.h"
#include "fusedet/drivers/log/recorder.h"
#include "fusedet/drivers/log/replay.h"

namespace fs = std::filesystem;
using namespace fusedet;
using namespace fusedet::drivers;
using namespace fusedet::drivers::logs;

namespace {

constexpr std::int64_t kT0 = 2'000'000'000;
constexpr int kBaud = 500000;
constexpr int kScans = 30;

// Range of beam b of scan s [mm]: easy to check, inside the 13-bit range.
std::uint16_t rangeMm(int s, int b) { return static_cast<std::uint16_t>(1000 + 10 * s + b); }

// A B0 telegram (180 deg / 1 deg, mm) of scan s, as the device sends it.
std::vector<std::uint8_t> scanTelegram(int s) {
  lms291::MeasuredValues v;
  v.countWord.count = 181;
  v.countWord.unit = lms291::Unit::kMm;
  for (int b = 0; b < 181; ++b) v.values.push_back(rangeMm(s, b));
  lms291::Telegram t;
  t.address = 0x80;
  t.command = lms291::kMeasuredValues;
  t.data = lms291::encodeMeasuredValues(v);
  t.status = 0x10;
  return lms291::encode(t);
}

struct Sample {
  fs::path path;
  std::vector<std::int64_t> scanStarts;  // when each telegram's first byte went on the line
};

// 30 scans at 75 Hz, each telegram delivered in 64-byte reads stamped when their last byte
// arrived; a garbage byte between scans; TPDOs at 100 Hz; 3 camera frames.
Sample writeLog(const std::string& name, mcap::WriterOptions o = {}) {
  Sample out;
  out.path = fs::temp_directory_path() / ("fusedet_replay_" + std::to_string(::getpid()) + "_" + name);
  Recorder rec(out.path, o, std::chrono::milliseconds(0));
  rec.setRig("version: 1\n", "image_width: 2\n");
  const std::int64_t byteNs = 20'000;  // 10 bits at 500 kbaud
  for (int s = 0; s < kScans; ++s) {
    const std::int64_t start = kT0 + s * 13'333'333;
    out.scanStarts.push_back(start);
    std::vector<std::uint8_t> bytes = scanTelegram(s);
    if (s % 5 == 2) bytes.insert(bytes.begin(), 0x55), out.scanStarts.back() += byteNs;  // line noise first
    for (std::size_t at = 0; at < bytes.size(); at += 64) {
      const std::size_t n = std::min<std::size_t>(64, bytes.size() - at);
      rec.record(SerialChunk{Stamp{start + static_cast<std::int64_t>(at + n) * byteNs}, "/dev/ttyUSB0", kBaud,
                             {bytes.begin() + static_cast<long>(at), bytes.begin() + static_cast<long>(at + n)}});
    }
  }
  for (int i = 0; i < 40; ++i) {
    rec.record(CanMessage{Stamp{kT0 + i * 10'000'000}, "can0", 0x080, false, false, false, {}});
    // TPDO1 as the drive maps it: position counts (default units: 4096 x 50 counts per turn) + statusword 0x1637
    const auto u = static_cast<std::uint32_t>(std::lround(0.01 * i * 4096 * 50 / (2 * M_PI)));
    rec.record(CanMessage{Stamp{kT0 + i * 10'000'000 + 300'000}, "can0", 0x185, false, false, false,
                          {static_cast<std::uint8_t>(u), static_cast<std::uint8_t>(u >> 8), static_cast<std::uint8_t>(u >> 16),
                           static_cast<std::uint8_t>(u >> 24), 0x37, 0x16}});
  }
  for (int i = 0; i < 3; ++i) {
    CameraFrame f;
    f.stamp = Stamp{kT0 + i * 100'000'000};
    f.sequence = static_cast<std::uint64_t>(i);
    f.width = 2;
    f.height = 1;
    f.stride = 4;
    f.format = PixelFormat::kYuyv;
    f.bytes = {16, 128, static_cast<std::uint8_t>(i), 128};
    rec.record(f);
  }
  rec.record(TiltSample{Stamp{kT0}, 1, 0});  // a decoded channel: replay skips it
  rec.close();
  return out;
}

SensorReplayConfig rig() {
  SensorReplayConfig c;
  c.laser.variant = lms291::Variant{180, 100};
  c.laser.remission = false;
  return c;
}

struct Collected {
  std::vector<LaserScan> scans;
  std::vector<TiltSample> tilt;
  std::vector<CameraFrame> frames;
  std::vector<std::int64_t> order;  // stamps in delivery order
  SensorReplayCounters counters;    // at the end
};

Collected replayAll(const fs::path& p, ReplayOptions o = {}, const std::atomic<bool>* stop = nullptr) {
  Collected c;
  SensorReplay r(p, rig(), o);
  SensorReplay::Handlers h;
  h.scan = [&](const LaserScan& s) { c.scans.push_back(s); };
  h.tilt = [&](const TiltSample& t) { c.tilt.push_back(t), c.order.push_back(t.stamp.ns); };
  h.frame = [&](const CameraFrame& f) { c.frames.push_back(f), c.order.push_back(f.stamp.ns); };
  r.run(h, stop);
  c.counters = r.counters();
  return c;
}

}  // namespace

TEST(Replay, LiveDecodersGiveBackWhatWasRecorded) {
  const Sample s = writeLog("decode.mcap");
  SensorReplay r(s.path, rig());
  Collected c;
  SensorReplay::Handlers h;
  h.scan = [&](const LaserScan& x) { c.scans.push_back(x); };
  h.tilt = [&](const TiltSample& t) { c.tilt.push_back(t); };
  h.frame = [&](const CameraFrame& f) { c.frames.push_back(f); };
  r.run(h);
  ASSERT_EQ(c.scans.size(), static_cast<std::size_t>(kScans));
  for (int i = 0; i < kScans; ++i) {
    const LaserScan& x = c.scans[static_cast<std::size_t>(i)];
    ASSERT_EQ(x.size(), 181u);
    EXPECT_NEAR(x.ranges[7], rangeMm(i, 7) * 1e-3, 1e-6);
    EXPECT_EQ(x.stamp.ns, s.scanStarts[static_cast<std::size_t>(i)]) << "scan " << i;  // end of telegram - line time
    EXPECT_EQ(x.sequence, static_cast<std::uint64_t>(i));
    EXPECT_EQ(x.status, 0x10);
    EXPECT_NEAR(x.startAngle, 0, 1e-12);
  }
  ASSERT_EQ(c.tilt.size(), 40u);
  EXPECT_NEAR(c.tilt[25].angle, 0.25, 1e-3);  // counts quantise to 2 pi / 204800 rad
  EXPECT_EQ(c.tilt[25].stamp.ns, kT0 + 25 * 10'000'000 + 300'000);
  EXPECT_NEAR(c.tilt[25].velocity, 1.0, 0.05);
  ASSERT_EQ(c.frames.size(), 3u);
  EXPECT_EQ(c.frames[2].bytes[2], 2);
  const SensorReplayCounters n = r.counters();
  EXPECT_EQ(n.scans, static_cast<std::uint64_t>(kScans));
  EXPECT_EQ(n.telegrams.crcErrors, 0u);
  EXPECT_EQ(n.telegrams.skippedBytes, 6u);  // the six noise bytes
  EXPECT_EQ(n.raw.otherMessages, 1u);
  EXPECT_EQ(n.raw.cameraFrames, 3u);
  ASSERT_TRUE(r.source().rig());
  EXPECT_EQ(r.source().rig()->cameraYaml, "image_width: 2\n");
}

TEST(Replay, DeterministicAndInStampOrder) {
  const Sample s = writeLog("determinism.mcap");
  const Collected a = replayAll(s.path), b = replayAll(s.path);
  ASSERT_EQ(a.order, b.order);
  EXPECT_TRUE(std::is_sorted(a.order.begin(), a.order.end()));
  ASSERT_EQ(a.scans.size(), b.scans.size());
  for (std::size_t i = 0; i < a.scans.size(); ++i) {
    EXPECT_EQ(a.scans[i].stamp, b.scans[i].stamp);
    EXPECT_EQ(a.scans[i].ranges, b.scans[i].ranges);
  }
}

TEST(Replay, RewoundReplayRepeatsTheFirstPassWithFreshCounters) {
  const Sample s = writeLog("rewind.mcap");
  const Collected fresh = replayAll(s.path);
  SensorReplay r(s.path, rig());
  Collected c;
  SensorReplay::Handlers h;
  h.scan = [&](const LaserScan& x) { c.scans.push_back(x); };
  h.tilt = [&](const TiltSample& t) { c.tilt.push_back(t), c.order.push_back(t.stamp.ns); };
  h.frame = [&](const CameraFrame& f) { c.frames.push_back(f), c.order.push_back(f.stamp.ns); };
  r.run(h);
  const SensorReplayCounters first = r.counters();
  // Stop in the middle of a pass (a telegram may be half read), then rewind: the same again.
  c = {};
  for (int i = 0; i < 20; ++i) r.step(h);
  r.rewind();
  c = {};
  r.run(h);
  ASSERT_EQ(c.order, fresh.order);
  ASSERT_EQ(c.scans.size(), static_cast<std::size_t>(kScans));
  for (std::size_t i = 0; i < c.scans.size(); ++i) {
    EXPECT_EQ(c.scans[i].stamp, fresh.scans[i].stamp);
    EXPECT_EQ(c.scans[i].sequence, fresh.scans[i].sequence);
    EXPECT_EQ(c.scans[i].ranges, fresh.scans[i].ranges);
  }
  const SensorReplayCounters again = r.counters();
  EXPECT_EQ(again.scans, first.scans);
  EXPECT_EQ(again.raw.messages, first.raw.messages);
  EXPECT_EQ(again.raw.cameraFrames, 3u);
  EXPECT_EQ(again.tiltSamples, first.tiltSamples);
  EXPECT_EQ(again.telegrams.skippedBytes, 6u);  // the six noise bytes, counted once
  // Re-stamping starts anew too: a rewound pass is shifted to the time it starts.
  ReplayOptions o;
  o.restamp = true;
  SensorReplay late(s.path, rig(), o);
  Collected d;
  SensorReplay::Handlers hd;
  hd.scan = [&](const LaserScan& x) { d.scans.push_back(x); };
  late.run(hd);
  std::this_thread::sleep_for(std::chrono::milliseconds(50));
  const std::int64_t firstPass = d.scans[0].stamp.ns;
  d = {};
  late.rewind();
  late.run(hd);
  EXPECT_GE(d.scans[0].stamp.ns - firstPass, 50'000'000);
  // ... or from a given time (a looping replay that ran ahead of the clock).
  const std::int64_t from = Stamp::now().ns + 3'600'000'000'000;
  d = {};
  late.rewind(from);
  late.run(hd);
  EXPECT_GE(d.scans[0].stamp.ns, from);
  EXPECT_LT(d.scans[0].stamp.ns, from + 1'000'000'000);
}

TEST(Replay, RealtimePacingAndStop) {
  const Sample s = writeLog("pacing.mcap");  // 0.39 s of data
  ReplayOptions o;
  o.realtime = true;
  auto t0 = std::chrono::steady_clock::now();
  const Collected paced = replayAll(s.path, o);
  const double pacedS = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_GE(pacedS, 0.38);  // never early; lateness under load is allowed
  EXPECT_EQ(paced.scans.size(), static_cast<std::size_t>(kScans));
  o.speed = 4;
  t0 = std::chrono::steady_clock::now();
  replayAll(s.path, o);
  EXPECT_GE(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 0.095);
  std::atomic<bool> stop{true};
  EXPECT_TRUE(replayAll(s.path, o, &stop).scans.empty());
}

TEST(Replay, RestampShiftsEverythingByOneOffset) {
  const Sample s = writeLog("restamp.mcap");
  ReplayOptions o;
  o.restamp = true;
  const Collected a = replayAll(s.path), b = replayAll(s.path, o);
  ASSERT_EQ(a.scans.size(), b.scans.size());
  const std::int64_t shift = b.scans[0].stamp - a.scans[0].stamp;
  EXPECT_GT(b.scans[0].stamp.ns, Stamp::now().ns - 60'000'000'000);
  for (std::size_t i = 0; i < a.scans.size(); ++i) EXPECT_EQ(b.scans[i].stamp - a.scans[i].stamp, shift);

  // restampFromNs later than now (a looping replay's next pass): the same offsets, starting there.
  o.restampFromNs = Stamp::now().ns + 3'600'000'000'000;
  const Collected c = replayAll(s.path, o);
  ASSERT_EQ(a.scans.size(), c.scans.size());
  const std::int64_t later = c.scans[0].stamp - a.scans[0].stamp;
  // The log's first message (its time) is stamped restampFromNs; the first scan lies within a second of it.
  EXPECT_NEAR(static_cast<double>(c.scans[0].stamp.ns - o.restampFromNs), 0.0, 1e9);
  EXPECT_GT(later, shift + 3'500'000'000'000);
  for (std::size_t i = 0; i < a.scans.size(); ++i) EXPECT_EQ(c.scans[i].stamp - a.scans[i].stamp, later);
}

namespace {

// The laser line of `kScans` scans at 75 Hz (scan s's telegram starts at kT0 + s x 13.33 ms
// + `delay` from scan `delayFrom` on), one byte every 20 us; `noiseAfter` bytes follow scan
// `noiseAt`'s telegram. Reads are those of a reader on time: 64 bytes at most, stamped when their
// last byte arrived - except that scan `lateAt`'s telegram is read late: its first 64 bytes on
// time, then nothing until scan `lateAt + 3`'s telegram has arrived, which is read together with
// the rest in one read (a reader thread descheduled for ~40 ms).
struct Line {
  int delayFrom = kScans;
  std::int64_t delay = 0;
  int noiseAt = -1;
  std::vector<std::uint8_t> noiseAfter;
  int lateAt = -1;
};
Sample writeLine(const std::string& name, const Line& line) {
  Sample out;
  out.path = fs::temp_directory_path() / ("fusedet_replay_" + std::to_string(::getpid()) + "_" + name);
  Recorder rec(out.path, {}, std::chrono::milliseconds(0));
  const std::int64_t byteNs = 20'000;
  std::vector<std::uint8_t> pending;  // bytes a late read has not taken yet
  for (int s = 0; s < kScans; ++s) {
    const std::int64_t start = kT0 + s * 13'333'333 + (s >= line.delayFrom ? line.delay : 0);
    out.scanStarts.push_back(start);
    std::vector<std::uint8_t> bytes = scanTelegram(s);
    if (s == line.noiseAt) bytes.insert(bytes.end(), line.noiseAfter.begin(), line.noiseAfter.end());
    for (std::size_t at = 0; at < bytes.size(); at += 64) {
      const std::size_t n = std::min<std::size_t>(64, bytes.size() - at);
      pending.insert(pending.end(), bytes.begin() + static_cast<long>(at), bytes.begin() + static_cast<long>(at + n));
      const bool held = line.lateAt >= 0 && s >= line.lateAt && s < line.lateAt + 3 && !(s == line.lateAt && at == 0);
      const bool lastOfLate = s == line.lateAt + 3 && at + n == bytes.size();
      if (held || (s == line.lateAt + 3 && !lastOfLate)) continue;
      rec.record(SerialChunk{Stamp{start + static_cast<std::int64_t>(at + n) * byteNs}, "/dev/ttyUSB0", kBaud, pending});
      pending.clear();
    }
  }
  rec.close();
  return out;
}

void expectEveryScanInOrder(const Collected& c) {
  ASSERT_EQ(c.scans.size(), static_cast<std::size_t>(kScans));
  for (int i = 0; i < kScans; ++i) {
    EXPECT_NEAR(c.scans[static_cast<std::size_t>(i)].ranges[7], rangeMm(i, 7) * 1e-3, 1e-6) << "scan " << i;
    EXPECT_EQ(c.scans[static_cast<std::size_t>(i)].sequence, static_cast<std::uint64_t>(i));
  }
}

}  // namespace

// A reader thread that was late reads a telegram's rest ~40 ms after its start: the live link saw
// no silence and completed the telegram, and so must replay (it used to take the gap between the
// two reads for a silence and give the telegram up: one recorded scan fewer, and every later scan
// paired with the live scan before it - the rig test's stamp failures under load).
TEST(Replay, TelegramReadLateInTwoPiecesIsNotGivenUp) {
  Line line;
  line.lateAt = 10;
  const Sample s = writeLine("late.mcap", line);
  const Collected c = replayAll(s.path);
  expectEveryScanInOrder(c);
  EXPECT_EQ(c.counters.telegrams.expired, 0u);
  EXPECT_EQ(c.counters.telegrams.skippedBytes, 0u);
  // Scans read on time keep their line stamps; scan 13's telegram ends its late read.
  for (int i : {0, 9, 13, 14, 29}) EXPECT_EQ(c.scans[static_cast<std::size_t>(i)].stamp.ns, s.scanStarts[static_cast<std::size_t>(i)]) << i;
  for (int i = 10; i < 14; ++i) EXPECT_LT(c.scans[static_cast<std::size_t>(i) - 1].stamp, c.scans[static_cast<std::size_t>(i)].stamp);
  fs::remove(s.path);
}

// Garbage that looks like the start of a long frame (STX, device address, length 400), then 30 ms
// of silence: the live link gives it up after the silence; replay rejects it by its CRC once the
// 406 bytes it claims have come and searches them again - the same telegrams with their line stamps.
TEST(Replay, GarbageFrameBeforeASilenceCostsNoTelegram) {
  Line line;
  line.noiseAt = 19;
  line.noiseAfter = {lms291::kStx, 0x80, 0x90, 0x01};
  line.delayFrom = 20;
  line.delay = 30'000'000;
  const Sample s = writeLine("garbage.mcap", line);
  const Collected c = replayAll(s.path);
  expectEveryScanInOrder(c);
  for (int i = 0; i < kScans; ++i)
    EXPECT_EQ(c.scans[static_cast<std::size_t>(i)].stamp.ns, s.scanStarts[static_cast<std::size_t>(i)]) << "scan " << i;
  EXPECT_EQ(c.counters.telegrams.crcErrors, 1u);
  EXPECT_EQ(c.counters.telegrams.skippedBytes, 4u);  // the garbage: 02 80 90 01
  fs::remove(s.path);
}

TEST(Replay, CutLogReplaysItsCompleteChunks) {
  mcap::WriterOptions o;
  o.chunkBytes = 4096;
  const Sample s = writeLog("cut.mcap", o);
  const auto size = fs::file_size(s.path);
  const Collected whole = replayAll(s.path);
  fs::resize_file(s.path, size * 2 / 3);
  SensorReplay r(s.path, rig());
  ASSERT_TRUE(r.source().index().truncation.has_value());
  std::size_t scans = 0;
  SensorReplay::Handlers h;
  h.scan = [&](const LaserScan& x) {
    EXPECT_EQ(x.ranges, whole.scans[scans].ranges);  // a prefix of the whole log's scans
    ++scans;
  };
  r.run(h);
  EXPECT_GT(scans, 0u);
  EXPECT_LT(scans, whole.scans.size());
}

TEST(Replay, MissingOrForeignFileIsAnError) {
  EXPECT_THROW(LogSource("/nonexistent.mcap"), mcap::McapError);
  const fs::path p = fs::temp_directory_path() / ("fusedet_replay_text_" + std::to_string(::getpid()));
  std::ofstream(p) << "not a log";
  EXPECT_THROW(LogSource{p}, mcap::McapError);
  fs::remove(p);
}

// Replay decodes TPDO1 with the live drive's decoder and the log's tilt units; SYNC,
// heartbeats, SDO traffic and other nodes' frames give no samples, short TPDOs are counted.
TEST(Replay, TiltTpdoUnitsOtherFramesAndShortPdos) {
  const fs::path p = fs::temp_directory_path() / ("fusedet_replay_tpdo_" + std::to_string(::getpid()) + ".mcap");
  {
    Recorder rec(p, {}, std::chrono::milliseconds(0));
    auto can = [&](std::int64_t t, std::uint32_t id, std::vector<std::uint8_t> d) {
      rec.record(CanMessage{Stamp{t}, "can0", id, false, false, false, std::move(d)});
    };
    can(1'000, 0x000, {0x81, 3});                               // NMT reset node 3
    can(2'000, 0x703, {0x00});                                  // boot-up
    can(3'000, 0x603, {0x40, 0x00, 0x10, 0, 0, 0, 0, 0});       // SDO request
    can(4'000, 0x583, {0x43, 0x00, 0x10, 0, 0x92, 0x01, 0, 0});  // SDO response
    can(5'000, 0x080, {});                                      // SYNC
    can(5'100, 0x183, {0x58, 0x02, 0, 0, 0x37, 0x16});          // 600 counts
    can(6'000, 0x185, {1, 2, 3, 4, 5, 6});                      // another node's TPDO1
    can(250'005'100, 0x183, {0x70, 0xFE, 0xFF, 0xFF, 0x37, 0x16});  // -400 counts
    can(250'006'000, 0x183, {1, 2, 3, 4});                    // 4 bytes: no statusword
    rec.close();
  }
  SensorReplayConfig c;
  c.tilt.node = 3;
  c.tilt.units = {1000, 2.0, 100};  // (counts - 100) / 2000 rev
  SensorReplay r(p, c);
  std::vector<TiltSample> samples;
  SensorReplay::Handlers h;
  h.tilt = [&](const TiltSample& t) { samples.push_back(t); };
  r.run(h);
  ASSERT_EQ(samples.size(), 2u);
  EXPECT_EQ(samples[0].stamp.ns, 5'100);
  EXPECT_NEAR(samples[0].angle, M_PI / 2, 1e-12);   // (600 - 100) / 2000 rev
  EXPECT_NEAR(samples[1].angle, -M_PI / 2, 1e-12);  // (-400 - 100) / 2000 rev
  EXPECT_NEAR(samples[1].velocity, -4 * M_PI, 1e-9);  // -pi rad in 0.25 s
  EXPECT_EQ(r.counters().tiltSamples, 2u);
  EXPECT_EQ(r.counters().badTpdos, 1u);
  fs::remove(p);
}
