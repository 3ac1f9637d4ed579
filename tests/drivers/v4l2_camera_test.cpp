// SPDX-License-Identifier: Apache-2.0
// V4l2Camera and FrameStream against FakeV4l2Device (an in-memory V4L2 device written from the
// kernel API, sharing no code with the driver), and the kernel I/O layer's error paths on nodes
// that need no camera (a missing path, a regular file, /dev/null).

#include <gtest/gtest.h>
#include <linux/videodev2.h>

#include <atomic>
#include <fstream>
#include <mutex>
#include <random>
#include <thread>

#include "fake_v4l2_device.h"
#include "fusedet/drivers/v4l2/camera.h"
#include "fusedet/drivers/v4l2/device_list.h"
#include "fusedet/drivers/v4l2/frame_stream.h"

namespace {

using namespace fusedet::drivers::v4l2;
using fusedet::drivers::CameraFrame;
using fusedet::drivers::PixelFormat;
using fusedet::testing::FakeFrame;
using fusedet::testing::FakeV4l2Device;
using namespace std::chrono_literals;

CameraConfig configFor(std::string device) {
  CameraConfig c;
  c.device = std::move(device);
  return c;
}

struct Rig {
  std::unique_ptr<FakeV4l2Device> owned = std::make_unique<FakeV4l2Device>();
  FakeV4l2Device* fake = owned.get();
  std::unique_ptr<V4l2Camera> camera;
  V4l2Camera& make(CameraConfig c = {}) {
    c.device = c.device == "/dev/video0" ? "/dev/fake-video" : c.device;
    camera = std::make_unique<V4l2Camera>(c, std::move(owned));
    return *camera;
  }
};

TEST(V4l2Camera, StartsStreamingWithNegotiatedFormatRateAndFourBuffers) {
  Rig rig;
  auto info = rig.make().start();
  ASSERT_TRUE(info) << info.error().message();
  EXPECT_EQ(info->caps.driver, "fake");
  EXPECT_EQ(info->caps.card, "Fake Camera");
  EXPECT_EQ(info->format.fourcc, static_cast<std::uint32_t>(V4L2_PIX_FMT_YUYV));
  EXPECT_EQ(info->format.width, 640u);
  EXPECT_EQ(info->format.height, 480u);
  EXPECT_EQ(info->bytesPerLine, 1280u);
  EXPECT_EQ(info->interval, (Fraction{1, 15}));
  EXPECT_EQ(info->buffers, 4u);
  EXPECT_TRUE(rig.fake->streaming);
  EXPECT_EQ(rig.fake->format.pixelformat, static_cast<std::uint32_t>(V4L2_PIX_FMT_YUYV));
  EXPECT_EQ(rig.fake->interval.denominator, 15u);
  EXPECT_EQ(rig.fake->bufferCount, 4u);
  EXPECT_EQ(rig.fake->mapped, 4);
  EXPECT_EQ(rig.fake->queued.size(), 4u);
  EXPECT_EQ(rig.fake->count(VIDIOC_STREAMON), 1u);
  rig.camera->stop();
  EXPECT_FALSE(rig.fake->isOpen());
  EXPECT_EQ(rig.fake->mapped, 0);
  EXPECT_EQ(rig.fake->bufferCount, 0u);  // freed after unmapping (the kernel refuses the other order)
}

TEST(V4l2Camera, FramesCarryDriverStampBytesAndContinuousSequence) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  rig.fake->script = {FakeFrame{0, 0, -1, 5'000'123'000}, FakeFrame{1, 0, -1, 5'066'789'000}, FakeFrame{4, 0, -1, 5'266'000'000}};
  std::vector<CameraFrame> frames;
  for (int i = 0; i < 3; ++i) {
    auto f = cam.readFrame(100ms);
    ASSERT_TRUE(f) << f.error().message();
    frames.push_back(std::move(*f));
  }
  EXPECT_EQ(frames[0].stamp.ns, 5'000'123'000);
  EXPECT_EQ(frames[1].stamp.ns, 5'066'789'000);
  EXPECT_EQ(frames[0].sequence, 0u);
  EXPECT_EQ(frames[1].sequence, 1u);
  EXPECT_EQ(frames[2].sequence, 4u);  // two frames lost in the driver: the gap stays visible
  for (const CameraFrame& f : frames) {
    EXPECT_EQ(f.format, PixelFormat::kYuyv);
    EXPECT_EQ(f.width, 640);
    EXPECT_EQ(f.height, 480);
    EXPECT_EQ(f.stride, 1280);
    ASSERT_EQ(f.bytes.size(), 640u * 480 * 2);
  }
  EXPECT_EQ(frames[2].bytes[0], FakeV4l2Device::patternByte(4, 0));
  EXPECT_EQ(frames[2].bytes[1000], FakeV4l2Device::patternByte(4, 1000));
  EXPECT_EQ(frames[1].bytes[614399], FakeV4l2Device::patternByte(1, 614399));
  const CameraCounters c = cam.counters();
  EXPECT_EQ(c.frames, 3u);
  EXPECT_EQ(c.bytes, 3u * 614400);
  EXPECT_EQ(c.sequenceGaps, 1u);
  EXPECT_EQ(c.lostFrames, 2u);
  EXPECT_EQ(c.hostStamps, 0u);
  EXPECT_EQ(c.stampsBackwards, 0u);
  EXPECT_EQ(rig.fake->queued.size(), 4u);  // every buffer went straight back
}

TEST(V4l2Camera, StampsThatDoNotIncreaseAreCounted) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  rig.fake->script = {FakeFrame{0, 0, -1, 3'000'000'000}, FakeFrame{1, 0, -1, 2'000'000'000},
                      FakeFrame{2, 0, -1, 2'000'000'000}, FakeFrame{3, 0, -1, 2'000'001'000}};  // V4L2 stamps have microseconds
  for (int i = 0; i < 4; ++i) ASSERT_TRUE(cam.readFrame(100ms));
  EXPECT_EQ(cam.counters().stampsBackwards, 2u);
}

TEST(V4l2Camera, NonMonotonicStampsAreReplacedAndCounted) {
  Rig rig;
  rig.fake->timestampFlags = V4L2_BUF_FLAG_TIMESTAMP_COPY;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  rig.fake->script = {FakeFrame{0, 0, -1, 42}};
  const fusedet::Stamp before = fusedet::Stamp::now();
  auto f = cam.readFrame(100ms);
  ASSERT_TRUE(f);
  EXPECT_GE(f->stamp, before);
  EXPECT_LE(f->stamp, fusedet::Stamp::now());
  EXPECT_EQ(cam.counters().hostStamps, 1u);
}

// Found by fuzzing (issue 37, tests/fuzz/v4l2_answers.cpp): a driver's "monotonic" stamp of
// 271579372060572 s overflowed the conversion to nanoseconds (undefined behaviour; in practice a
// wrapped, negative stamp). Seconds or microseconds out of range are the dequeue time now, counted.
TEST(V4l2Camera, MonotonicStampsOutOfRangeAreReplacedAndCounted) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  FakeFrame huge{0}, negative{1}, badMicros{2}, fine{3, 0, -1, 7'000'000'000};
  huge.rawStamp = timeval{271579372060572, 0};
  negative.rawStamp = timeval{-5, 0};
  badMicros.rawStamp = timeval{5, 1'000'000};
  rig.fake->script = {huge, negative, badMicros, fine};
  const fusedet::Stamp before = fusedet::Stamp::now();
  for (int i = 0; i < 3; ++i) {
    auto f = cam.readFrame(100ms);
    ASSERT_TRUE(f);
    EXPECT_GE(f->stamp, before) << i;
    EXPECT_LE(f->stamp, fusedet::Stamp::now()) << i;
  }
  auto f = cam.readFrame(100ms);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->stamp.ns, 7'000'000'000);
  EXPECT_EQ(cam.counters().hostStamps, 3u);
}

TEST(V4l2Camera, ErrorAndShortBuffersAreSkippedCountedAndRecorded) {
  Rig rig;
  auto& cam = rig.make();
  std::vector<std::pair<std::uint32_t, std::size_t>> recorded;  // sequence, bytes
  cam.setRawHook([&](const RawBuffer& b) { recorded.emplace_back(b.sequence, b.bytes.size()); });
  ASSERT_TRUE(cam.start());
  rig.fake->script = {FakeFrame{0, V4L2_BUF_FLAG_ERROR}, FakeFrame{1, 0, 1000}, FakeFrame{2, 0, 0}, FakeFrame{3}};
  auto f = cam.readFrame(100ms);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->sequence, 3u);
  const CameraCounters c = cam.counters();
  EXPECT_EQ(c.errorFrames, 1u);
  EXPECT_EQ(c.shortFrames, 2u);
  EXPECT_EQ(c.frames, 1u);
  EXPECT_EQ(c.lostFrames, 0u);
  ASSERT_EQ(recorded.size(), 4u);
  EXPECT_EQ(recorded[0], std::make_pair(0u, std::size_t{614400}));
  EXPECT_EQ(recorded[1], std::make_pair(1u, std::size_t{1000}));
  EXPECT_EQ(recorded[3], std::make_pair(3u, std::size_t{614400}));
}

TEST(V4l2Camera, DequeueAnswersAgainstTheBookkeeping) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  rig.fake->script = {FakeFrame{0, 0, -1, 1, 9}};  // index 9 of 4
  auto f = cam.readFrame(100ms);
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, std::errc::protocol_error);
  EXPECT_EQ(f.error().context, "camera /dev/fake-video: the driver returned buffer 9 of 4");
  EXPECT_EQ(cam.counters().bufferErrors, 1u);
}

// A driver answering DQBUF with random sequence numbers, flags, sizes and bad indices: every buffer
// ends up counted exactly once (frame, error, short or bookkeeping error), nothing crashes, and a
// stream restart recovers from every refused answer.
TEST(V4l2Camera, FuzzedDequeueAnswers) {
  Rig rig;
  rig.fake->formats = {{V4L2_PIX_FMT_YUYV, "YUYV 4:2:2", {{64, 48}}, {{1, 15}}}};  // small: 3000 buffers stay quick
  CameraConfig config;
  config.width = 64;
  config.height = 48;
  auto& cam = rig.make(config);
  ASSERT_TRUE(cam.start());
  std::mt19937 rng(5);
  const std::size_t image = 64 * 48 * 2;
  constexpr int kBuffers = 3000;
  for (int i = 0; i < kBuffers; ++i) {
    FakeFrame f;
    f.sequence = rng() % 4 == 0 ? static_cast<std::uint32_t>(rng()) : static_cast<std::uint32_t>(i);
    f.extraFlags = rng() % 10 == 0 ? V4L2_BUF_FLAG_ERROR : 0;
    f.bytesUsed = rng() % 5 == 0 ? static_cast<std::int64_t>(rng() % (image + 100)) : -1;
    // Out of range (4 buffers): a wrong index in range is indistinguishable from a right one.
    f.forceIndex = rng() % 20 == 0 ? static_cast<std::int64_t>(4 + rng() % 100) : -1;
    f.stampNs = 1'000'000'000 + static_cast<std::int64_t>(rng() % 1'000'000'000);
    rig.fake->script.push_back(f);
  }
  std::uint64_t delivered = 0, refused = 0;
  while (!rig.fake->script.empty()) {
    auto f = cam.readFrame(50ms);
    if (f) {
      ++delivered;
      ASSERT_EQ(f->bytes.size(), image);
      continue;
    }
    if (f.error().code == std::errc::timed_out) {  // the last buffers were skipped ones
      ASSERT_TRUE(rig.fake->script.empty());
      break;
    }
    ++refused;
    ASSERT_TRUE(cam.restartStream()) << f.error().message();
  }
  const CameraCounters c = cam.counters();
  EXPECT_EQ(c.frames, delivered);
  EXPECT_EQ(c.bufferErrors, refused);
  EXPECT_EQ(c.frames + c.errorFrames + c.shortFrames + c.bufferErrors, static_cast<std::uint64_t>(kBuffers));
  EXPECT_GT(c.frames, 1000u);
  EXPECT_GT(c.bufferErrors, 10u);
  EXPECT_GT(c.lostFrames, 0u);
}

TEST(V4l2Camera, PollTimeoutIsTimedOut) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  auto f = cam.readFrame(5ms);
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, std::errc::timed_out);
  EXPECT_EQ(f.error().context, "camera /dev/fake-video: no frame within 5 ms");
  EXPECT_EQ(cam.counters().timeouts, 1u);
}

TEST(V4l2Camera, RestartStreamRequeuesAndRestartsTheSequence) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  rig.fake->script = {FakeFrame{0}, FakeFrame{1}};
  ASSERT_TRUE(cam.readFrame(100ms));
  ASSERT_TRUE(cam.readFrame(100ms));
  ASSERT_TRUE(cam.restartStream());
  EXPECT_EQ(rig.fake->count(VIDIOC_STREAMOFF), 1u);
  EXPECT_EQ(rig.fake->count(VIDIOC_STREAMON), 2u);
  EXPECT_EQ(rig.fake->queued.size(), 4u);
  rig.fake->script = {FakeFrame{0}, FakeFrame{1}};  // the driver counts from 0 again
  auto f = cam.readFrame(100ms);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->sequence, 2u);
  const CameraCounters c = cam.counters();
  EXPECT_EQ(c.sequenceResets, 0u);
  EXPECT_EQ(c.lostFrames, 0u);
  EXPECT_EQ(c.streamStarts, 2u);
}

TEST(V4l2Camera, VanishedDeviceIsNoSuchDevice) {
  Rig rig;
  auto& cam = rig.make();
  ASSERT_TRUE(cam.start());
  rig.fake->vanished = true;
  auto f = cam.readFrame(100ms);
  ASSERT_FALSE(f);
  EXPECT_EQ(f.error().code, std::errc::no_such_device);
  EXPECT_EQ(f.error().message().rfind("camera /dev/fake-video: VIDIOC_DQBUF", 0), 0u) << f.error().message();
  cam.stop();  // must not throw or hang on a dead device
  EXPECT_EQ(rig.fake->mapped, 0);
}

TEST(V4l2Camera, RefusesWhatItCannotCaptureFrom) {
  {
    Rig rig;
    rig.fake->notV4l2 = true;
    auto r = rig.make().start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().context, "camera /dev/fake-video: not a V4L2 device (VIDIOC_QUERYCAP refused)");
  }
  {
    Rig rig;
    rig.fake->deviceCaps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;  // a UVC metadata node
    auto r = rig.make().start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, std::errc::operation_not_supported);
    EXPECT_EQ(r.error().context,
              "camera /dev/fake-video (fake, Fake Camera): not a video capture device (it offers: metadata capture, streaming)");
  }
  {
    Rig rig;
    rig.fake->deviceCaps = V4L2_CAP_VIDEO_CAPTURE_MPLANE | V4L2_CAP_STREAMING;
    auto r = rig.make().start();
    ASSERT_FALSE(r);
    EXPECT_NE(r.error().context.find("multi-planar capture only"), std::string::npos);
  }
  {
    Rig rig;
    rig.fake->deviceCaps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_READWRITE;
    auto r = rig.make().start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().context,
              "camera /dev/fake-video (fake, Fake Camera): no streaming I/O (it offers: video capture, read/write)");
  }
  {
    Rig rig;
    rig.fake->maxBuffers = 2;
    auto r = rig.make().start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().context, "camera /dev/fake-video: asked for 4 capture buffers, the device granted 2 (need at least 4)");
    EXPECT_EQ(rig.fake->mapped, 0);
    EXPECT_FALSE(rig.fake->isOpen());
  }
}

TEST(V4l2Camera, FormatRefusalNamesDeviceAndOffers) {
  Rig rig;
  CameraConfig c;
  c.format = FormatChoice::kMjpeg;
  auto r = rig.make(c).start();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, std::errc::invalid_argument);
  EXPECT_EQ(r.error().context, "camera /dev/fake-video: wants MJPEG; the device offers YUYV (640x480 1280x720)");
  EXPECT_EQ(rig.fake->count(VIDIOC_S_FMT), 0u);
  EXPECT_FALSE(rig.fake->isOpen());
}

TEST(V4l2Camera, MjpegFramesKeepTheirCompressedSize) {
  Rig rig;
  rig.fake->formats = {{V4L2_PIX_FMT_MJPEG, "Motion-JPEG", {{1280, 720}}, {{1, 30}}}};
  CameraConfig c;
  c.format = FormatChoice::kAuto;
  c.width = 1024;
  c.height = 768;
  auto info = rig.make(c).start();
  ASSERT_TRUE(info) << info.error().message();
  EXPECT_EQ(info->format.width, 1280u);
  ASSERT_FALSE(info->notes.empty());
  EXPECT_EQ(info->notes[0], "size 1024x768 is not offered; using 1280x720");
  EXPECT_EQ(info->notes[1], "asked for 15 fps; the device runs at 1/30 s per frame");
  rig.fake->script = {FakeFrame{0, 0, 12345}};
  auto f = rig.camera->readFrame(100ms);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->format, PixelFormat::kMjpeg);
  EXPECT_EQ(f->stride, 0);
  EXPECT_EQ(f->bytes.size(), 12345u);
}

TEST(V4l2Camera, ControlsAppliedFromConfig) {
  Rig rig;
  v4l2_queryctrl mode{};
  mode.id = V4L2_CID_EXPOSURE_AUTO;
  mode.type = V4L2_CTRL_TYPE_MENU;
  mode.minimum = 0;
  mode.maximum = 3;
  v4l2_queryctrl absolute{};
  absolute.id = V4L2_CID_EXPOSURE_ABSOLUTE;
  absolute.type = V4L2_CTRL_TYPE_INTEGER;
  absolute.minimum = 3;
  absolute.maximum = 2047;
  absolute.step = 1;
  rig.fake->controls = {{V4L2_CID_EXPOSURE_AUTO, mode}, {V4L2_CID_EXPOSURE_ABSOLUTE, absolute}};
  rig.fake->menus[V4L2_CID_EXPOSURE_AUTO] = {1, 3};
  CameraConfig c;
  c.controls.exposure = {false, 20000};
  c.controls.gain = {false, 7};
  auto info = rig.make(c).start();
  ASSERT_TRUE(info);
  const std::vector<std::pair<std::uint32_t, std::int32_t>> want{{V4L2_CID_EXPOSURE_AUTO, 1}, {V4L2_CID_EXPOSURE_ABSOLUTE, 200}};
  EXPECT_EQ(rig.fake->controlWrites, want);
  ASSERT_EQ(info->notes.size(), 1u);
  EXPECT_EQ(info->notes[0], "gain: the device has no gain control; fixed gain 7 not applied");
}

TEST(V4l2Camera, ConfigValidation) {
  CameraConfig c;
  EXPECT_EQ(c.validate(), "");
  c.buffers = 3;
  EXPECT_EQ(c.validate(), "camera: buffers 3 outside 4..32");
  c = {};
  c.fps = 0;
  EXPECT_NE(c.validate(), "");
  c = {};
  c.controls.exposure = {false, 0};
  EXPECT_EQ(c.validate(), "camera: a fixed exposure must be > 0 us");
  Rig rig;
  CameraConfig bad;
  bad.width = 8;
  auto r = rig.make(bad).start();
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, std::errc::invalid_argument);
}

TEST(V4l2DeviceList, DescribesFormatsSizesAndIntervals) {
  auto fake = std::make_unique<FakeV4l2Device>();
  fake->formats.push_back({V4L2_PIX_FMT_MJPEG, "Motion-JPEG", {{1920, 1080}}, {{1, 30}}});
  const CameraDescription d = describeCamera("/dev/fake-video", std::move(fake));
  ASSERT_TRUE(d.usable()) << d.error;
  ASSERT_EQ(d.formats.size(), 2u);
  EXPECT_EQ(d.formats[1].description, "Motion-JPEG");
  ASSERT_EQ(d.intervals.size(), 3u);
  EXPECT_EQ(d.intervals[1].width, 1280u);
  ASSERT_EQ(d.intervals[1].intervals.size(), 2u);
  EXPECT_EQ(d.intervals[1].intervals[0].min, (Fraction{1, 30}));
  auto meta = std::make_unique<FakeV4l2Device>();
  meta->deviceCaps = V4L2_CAP_META_CAPTURE | V4L2_CAP_STREAMING;
  const CameraDescription m = describeCamera("/dev/fake-meta", std::move(meta));
  EXPECT_FALSE(m.usable());
  EXPECT_NE(m.error.find("not a video capture device"), std::string::npos);
}

TEST(V4l2DeviceList, FindsVideoNodesInNumericOrder) {
  const auto dir = std::filesystem::temp_directory_path() / ("fusedet-devlist-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const char* n : {"video10", "video2", "video0", "videoX", "vide", "video", "ttyUSB0"}) std::ofstream(dir / n).put('x');
  const auto nodes = listVideoNodes(dir);
  std::filesystem::remove_all(dir);
  ASSERT_EQ(nodes.size(), 3u);
  EXPECT_EQ(nodes[0], (dir / "video0").string());
  EXPECT_EQ(nodes[1], (dir / "video2").string());
  EXPECT_EQ(nodes[2], (dir / "video10").string());
  EXPECT_TRUE(listVideoNodes(dir).empty());  // gone: no nodes, no exception
}

// The kernel layer on nodes every machine has: the errors the CLI and the daemon report.
TEST(V4l2KernelIo, ErrorsWithoutACamera) {
  {
    V4l2Camera cam(configFor("/nonexistent/video7"));
    auto r = cam.start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, std::errc::no_such_file_or_directory);
    EXPECT_EQ(r.error().context, "camera /nonexistent/video7: open");
  }
  {
    const auto file = std::filesystem::temp_directory_path() / ("fusedet-notdev-" + std::to_string(::getpid()));
    std::ofstream(file).put('x');
    V4l2Camera cam(configFor(file.string()));
    auto r = cam.start();
    std::filesystem::remove(file);
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, std::errc::inappropriate_io_control_operation);
    EXPECT_EQ(r.error().context, "camera " + file.string() + ": not a character device");
  }
  {
    V4l2Camera cam(configFor("/dev/null"));  // a character device, but no V4L2
    auto r = cam.start();
    ASSERT_FALSE(r);
    EXPECT_EQ(r.error().code, std::errc::inappropriate_io_control_operation);
    EXPECT_EQ(r.error().context, "camera /dev/null: not a V4L2 device (VIDIOC_QUERYCAP refused)");
  }
}

// FrameStream: a stall is met with stream restarts, then a reopen; an unplugged device (its node
// gone) is reopened once the node is back.
struct StreamRig {
  std::filesystem::path node =
      std::filesystem::temp_directory_path() / ("fusedet-fake-video-" + std::to_string(::getpid()));
  FakeV4l2Device* fake = nullptr;
  std::atomic<int> frames{0};
  std::unique_ptr<FrameStream> stream;
  explicit StreamRig(FrameStreamTiming timing) {
    std::ofstream(node).put('x');
    auto owned = std::make_unique<FakeV4l2Device>();
    fake = owned.get();
    fake->presenceFile = node;
    CameraConfig c;
    c.device = node.string();
    stream = std::make_unique<FrameStream>(c, [this](const CameraFrame&) { ++frames; }, timing, std::move(owned));
  }
  ~StreamRig() {
    stream->stop();
    std::filesystem::remove(node);
  }
  template <class P>
  bool waitFor(P pred, std::chrono::milliseconds limit = 5000ms) {
    const auto end = std::chrono::steady_clock::now() + limit;
    while (std::chrono::steady_clock::now() < end) {
      if (pred()) return true;
      std::this_thread::sleep_for(2ms);
    }
    return pred();
  }
};

TEST(V4l2FrameStream, StallRestartsTheStreamThenReopens) {
  FrameStreamTiming t;
  t.readTimeout = 5ms;
  t.stallLimit = 40ms;
  t.maxRestarts = 2;
  StreamRig rig(t);
  rig.stream->start();
  // No frame scripted: the stream stalls. Two restarts, then a reopen (second successful start).
  ASSERT_TRUE(rig.waitFor([&] { return rig.stream->counters().reopens >= 1; }));
  rig.stream->stop();
  const FrameStreamCounters c = rig.stream->counters();
  EXPECT_GE(c.streamRestarts, 2u);
  EXPECT_GE(c.stalls, 3u);
  EXPECT_EQ(c.lastError, "stalled");
  EXPECT_EQ(rig.stream->state(), fusedet::drivers::StreamState::kStopped);
  EXPECT_FALSE(rig.fake->isOpen());
}

TEST(V4l2FrameStream, ReopensAfterTheDeviceVanishesAndReturns) {
  FrameStreamTiming t;
  t.readTimeout = 5ms;
  t.stallLimit = 10s;
  StreamRig rig(t);
  for (std::uint32_t i = 0; i < 5; ++i) rig.fake->script.push_back(FakeFrame{i});
  rig.stream->start();
  ASSERT_TRUE(rig.waitFor([&] { return rig.frames.load() == 5; }));
  // Unplug: node gone, every call fails. The stream must notice, close and wait.
  std::filesystem::remove(rig.node);
  rig.fake->vanished = true;
  ASSERT_TRUE(rig.waitFor([&] { return rig.stream->counters().failedOpens >= 1; }));
  EXPECT_EQ(rig.stream->counters().camera.frames, 5u);
  EXPECT_NE(rig.stream->state(), fusedet::drivers::StreamState::kStreaming);
  // Plug back in (the thread only touches the fake between opens: it is waiting on the node now).
  rig.fake->vanished = false;
  rig.fake->addFrames({FakeFrame{0}, FakeFrame{1}, FakeFrame{2}});
  std::ofstream(rig.node).put('x');
  ASSERT_TRUE(rig.waitFor([&] { return rig.frames.load() == 8; }));
  const FrameStreamCounters c = rig.stream->counters();
  EXPECT_EQ(c.reopens, 1u);
  EXPECT_NE(c.lastError.find("No such file"), std::string::npos) << c.lastError;
}

// A USB camera named by VID:PID: the node is looked up before every open; while the device is
// absent nothing is opened and the lookup's reason leads the reported error; re-plugged, it may have a new node.
TEST(V4l2FrameStream, AResolverFindsTheNodeAnewAfterARePlug) {
  FrameStreamTiming t;
  t.readTimeout = 5ms;
  t.stallLimit = 10s;
  StreamRig rig(t);
  std::mutex m;
  std::string current;  // empty: the device is not plugged in
  const std::string absent = "usb 046d:0825: no such device connected";
  rig.stream->setDeviceResolver([&]() -> fusedet::Result<std::string> {
    std::lock_guard lock(m);
    if (current.empty()) return fusedet::makeError(std::errc::no_such_device, absent);
    return current;
  });
  for (std::uint32_t i = 0; i < 3; ++i) rig.fake->script.push_back(FakeFrame{i});
  rig.stream->start();
  ASSERT_TRUE(rig.waitFor([&] { return rig.stream->counters().lastError.rfind(absent, 0) == 0; }));
  EXPECT_TRUE(rig.fake->openedPaths().empty());
  {
    std::lock_guard lock(m);
    current = "/dev/fake-video0";
  }
  rig.stream->deviceArrived();
  ASSERT_TRUE(rig.waitFor([&] { return rig.frames.load() == 3; }));
  // Unplugged: every call fails and the lookup finds nothing.
  {
    std::lock_guard lock(m);
    current.clear();
  }
  rig.fake->vanished = true;
  ASSERT_TRUE(rig.waitFor([&] {
    return rig.stream->counters().lastError.rfind(absent, 0) == 0 && rig.stream->state() != fusedet::drivers::StreamState::kStreaming;
  }));
  // Re-plugged elsewhere: a new node.
  rig.fake->vanished = false;
  rig.fake->addFrames({FakeFrame{0}, FakeFrame{1}});
  {
    std::lock_guard lock(m);
    current = "/dev/fake-video3";
  }
  ASSERT_TRUE(rig.waitFor([&] { return rig.frames.load() == 5; }));
  EXPECT_EQ(rig.fake->openedPaths(), (std::vector<std::string>{"/dev/fake-video0", "/dev/fake-video3"}));
  EXPECT_EQ(rig.stream->counters().reopens, 1u);
}

}  // namespace
