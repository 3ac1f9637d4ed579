// SPDX-License-Identifier: Apache-2.0
// Recording beyond the laser: one Recorder takes, at the same time,
//  - the LMS 291 driver's raw serial reads (ScanStream::setRecorder) streaming from lms291-sim on
//    a pty,
//  - every CAN frame of the tilt drive (TiltDrive, the live master) nodding issue 11's CiA 402
//    motor simulator on a threaded in-process bus in real time (the bus's recording hook:
//    both directions),
//  - the camera buffers FrameStream delivers from a scripted in-memory V4L2 device,
// as `fusedet record` does. Replaying the file through SensorReplay must give back what the live
// drivers emitted: the same scans (values, sequence numbers, stamps), the same tilt samples
// (stamps, angles, velocities) and the same frames (stamps, sequence numbers, bytes).

#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include "../fake_v4l2_device.h"
#include "../lms291/sim/simulator.h"
#include "fusedet/drivers/canopen/inprocess_bus.h"
#include "fusedet/drivers/canopen/tilt_drive.h"
#include "fusedet/drivers/lms291/scan_stream.h"
#include "fusedet/drivers/log/candump.h"
#include "fusedet/drivers/log/mcap_reader.h"
#include "fusedet/drivers/log/recorder.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/drivers/v4l2/frame_stream.h"
#include "motor_simulator.h"

namespace fs = std::filesystem;
using namespace std::chrono_literals;
using namespace fusedet;
using namespace fusedet::drivers;

TEST(RecordReplay, TiltLaserAndCameraReplayAsRecorded) {
  char tmpl[] = "/tmp/fusedet-record-rig-XXXXXX";
  ASSERT_NE(mkdtemp(tmpl), nullptr);
  const fs::path dir = tmpl;
  const fs::path log = dir / "rig.mcap";

  lms291::sim::SimOptions so;
  so.link = (dir / "tty").string();
  lms291::sim::Simulator sim(so);
  ASSERT_TRUE(sim.start());
  lms291::Lms291Config laser;
  laser.device = so.link;
  laser.baud = 500000;
  laser.variant = {180, 100};
  laser.baudSwitchPause = 50ms;

  canopen::TiltDriveConfig tilt;
  tilt.node = 7;
  tilt.minDeg = -4;
  tilt.maxDeg = 4;
  tilt.speedDegS = 40;
  tilt.units = {2048, 30.0, 100};

  const fs::path node = dir / "video0";
  std::ofstream(node).put('x');
  auto device = std::make_unique<fusedet::testing::FakeV4l2Device>();
  device->presenceFile = node;
  const std::int64_t now = Stamp::now().ns;
  for (std::uint32_t i = 0; i < 8; ++i) device->script.push_back({i, 0, -1, now + i * 66'000'000, -1});
  v4l2::CameraConfig camera;
  camera.device = node.string();

  std::mutex m;
  std::vector<LaserScan> liveScans;
  std::vector<TiltSample> liveTilt;
  std::vector<CameraFrame> liveFrames;
  canopen::TiltDriveCounters driveCounters;
  lms291::ScanStreamCounters laserCounters;
  {
    logs::Recorder rec(log);
    lms291::ScanStream scans(laser, [&](const LaserScan& s) {
      std::lock_guard lock(m);
      liveScans.push_back(s);
    });
    scans.setRecorder(&rec);
    v4l2::FrameStream frames(camera, [&](const CameraFrame& f) {
      rec.record(f);
      std::lock_guard lock(m);
      liveFrames.push_back(f);
    }, {}, std::move(device));

    canopen::InProcessBus bus("can0");
    auto masterEnd = bus.connect();
    auto motorEnd = bus.connect();
    // The drive's bus is the one recorded: every frame it sends and receives (= all traffic).
    masterEnd->setFrameHook([&](const canopen::CanFrame& f, canopen::FrameDirection) { rec.record(logs::toCanMessage(f, "can0")); });
    canopen::sim::MotorSimOptions mo;
    mo.node = tilt.node;
    canopen::sim::MotorSimulator motor(*motorEnd, mo);
    canopen::TiltDrive drive(*masterEnd, tilt, [&](const TiltSample& s) {
      std::lock_guard lock(m);
      liveTilt.push_back(s);
    });
    std::atomic<bool> stop{false};
    std::thread motorThread([&] { (void)canopen::runNode(*motorEnd, motor, stop); });
    std::thread driveThread([&] { (void)canopen::runNode(*masterEnd, drive, stop); });
    drive.nod();
    drive.start();
    scans.start();
    frames.start();
    const auto end = std::chrono::steady_clock::now() + 30s;
    while (std::chrono::steady_clock::now() < end) {
      std::size_t scansSoFar = 0, framesSoFar = 0;
      {
        std::lock_guard lock(m);
        scansSoFar = liveScans.size();
        framesSoFar = liveFrames.size();
      }
      // Not under `m`: drive.counters() takes the drive's lock, and the drive calls the sample
      // handler (which takes `m`) under that lock - asking it while holding `m` deadlocked (seen
      // under load: this thread in counters(), the bus thread in the handler, each waiting).
      if (scansSoFar >= 60 && framesSoFar >= 8 && drive.counters().sweeps >= 2) break;
      std::this_thread::sleep_for(10ms);
    }
    drive.stop();
    for (int i = 0; i < 200 && !drive.stopped(); ++i) std::this_thread::sleep_for(10ms);
    std::this_thread::sleep_for(30ms);  // the last TPDOs in flight
    stop = true;
    motorThread.join();
    driveThread.join();
    driveCounters = drive.counters();
    frames.stop();
    auto stopped = scans.stop();  // the error says which step met silence (notes-flaky.md: pty stalls under load)
    EXPECT_TRUE(stopped) << stopped.error().message();
    laserCounters = scans.counters();
    rec.close();
    EXPECT_EQ(rec.error(), "");
  }
  ASSERT_GE(liveScans.size(), 60u);
  ASSERT_EQ(liveFrames.size(), 8u);
  EXPECT_GE(driveCounters.sweeps, 2u);
  EXPECT_EQ(driveCounters.faults, 0u) << driveCounters.lastFault;
  ASSERT_GT(liveTilt.size(), 50u);
  EXPECT_TRUE(mcap::McapReader(log).index().intact());

  logs::SensorReplayConfig rc;
  rc.laser = laser;
  rc.tilt = tilt;
  logs::SensorReplay replay(log, rc);
  std::vector<LaserScan> scans;
  std::vector<TiltSample> samples;
  std::vector<CameraFrame> frames;
  logs::SensorReplay::Handlers h;
  h.scan = [&](const LaserScan& s) { scans.push_back(s); };
  h.tilt = [&](const TiltSample& t) { samples.push_back(t); };
  h.frame = [&](const CameraFrame& f) { frames.push_back(f); };
  replay.run(h);
  std::printf("live: %zu scans, %zu tilt samples (%llu sweeps), %zu frames; replayed: %zu scans, %zu tilt samples, %zu "
              "frames from %llu CAN frames, %llu serial reads\n",
              liveScans.size(), liveTilt.size(), static_cast<unsigned long long>(driveCounters.sweeps), liveFrames.size(),
              scans.size(), samples.size(), frames.size(), static_cast<unsigned long long>(replay.counters().raw.canFrames),
              static_cast<unsigned long long>(replay.counters().raw.serialChunks));
  // The telegram readers of both sides: a frame given up (expired) or bytes skipped on one side
  // only is where the two scan lists part.
  const lms291::ReaderCounters& liveReader = laserCounters.device.link.reader;
  const lms291::ReaderCounters replayReader = replay.counters().telegrams;
  std::printf("telegram reader, live: %llu telegrams, %llu expired, %llu skipped bytes; replay: %llu telegrams, %llu "
              "expired, %llu skipped bytes\n",
              static_cast<unsigned long long>(liveReader.telegrams), static_cast<unsigned long long>(liveReader.expired),
              static_cast<unsigned long long>(liveReader.skippedBytes),
              static_cast<unsigned long long>(replayReader.telegrams),
              static_cast<unsigned long long>(replayReader.expired),
              static_cast<unsigned long long>(replayReader.skippedBytes));
  // Laser: the live scans are a prefix (replay also decodes telegrams passed over while stopping):
  // values, sequence numbers and stamps exactly - the replay feeds the recorded reads with their
  // stamps to the live link's telegram reader and scan decoder. (Under load, stamps used to differ
  // by 13 ms to 0.5 s: replay gave up a telegram whose rest was read late, and every later scan was
  // compared with the live scan before it - equal ranges and counted sequence numbers hid the shift.
  // Fixed in replay.cpp; the old two-scan-period bound only hid how far the lists had parted.)
  ASSERT_GE(scans.size(), liveScans.size());
  std::size_t stampsDiffer = 0;
  for (std::size_t i = 0; i < liveScans.size(); ++i) {
    stampsDiffer += scans[i].stamp != liveScans[i].stamp;
    EXPECT_EQ(scans[i].stamp, liveScans[i].stamp) << i;
    EXPECT_EQ(scans[i].sequence, liveScans[i].sequence) << i;
    EXPECT_EQ(scans[i].ranges, liveScans[i].ranges) << i;
  }
  std::printf("scan stamps: %zu of %zu differ from the live driver's\n", stampsDiffer, liveScans.size());
  // Tilt: every TPDO1 the drive decoded, decoded again from the recorded frames.
  ASSERT_EQ(samples.size(), liveTilt.size());
  for (std::size_t i = 0; i < samples.size(); ++i) {
    EXPECT_EQ(samples[i].stamp, liveTilt[i].stamp) << i;
    EXPECT_EQ(samples[i].angle, liveTilt[i].angle) << i;
    EXPECT_EQ(samples[i].velocity, liveTilt[i].velocity) << i;
  }
  // Camera: the buffers as captured.
  ASSERT_EQ(frames.size(), liveFrames.size());
  for (std::size_t i = 0; i < frames.size(); ++i) {
    EXPECT_EQ(frames[i].stamp, liveFrames[i].stamp) << i;
    EXPECT_EQ(frames[i].sequence, liveFrames[i].sequence) << i;
    EXPECT_EQ(frames[i].format, liveFrames[i].format) << i;
    EXPECT_EQ(frames[i].bytes, liveFrames[i].bytes) << i;
  }
  fs::remove_all(dir);
}
