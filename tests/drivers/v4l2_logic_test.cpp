// SPDX-License-Identifier: Apache-2.0
// The V4L2 driver's pure logic: format negotiation, buffer bookkeeping, sequence-gap counting,
// stall escalation and the exposure/gain plan. No device, no ioctl.

#include <gtest/gtest.h>
#include <linux/videodev2.h>

#include <random>

#include "fusedet/drivers/v4l2/buffer_ring.h"
#include "fusedet/drivers/v4l2/controls.h"
#include "fusedet/drivers/v4l2/negotiation.h"
#include "fusedet/drivers/v4l2/sequence_tracker.h"
#include "fusedet/drivers/v4l2/stall_policy.h"

namespace {

using namespace fusedet::drivers::v4l2;
using fusedet::drivers::PixelFormat;

// Codes written out from the kernel header, not from the driver's helper.
const std::uint32_t kYuyv = V4L2_PIX_FMT_YUYV, kMjpg = V4L2_PIX_FMT_MJPEG, kRgb3 = V4L2_PIX_FMT_RGB24,
                    kUyvy = V4L2_PIX_FMT_UYVY, kJpeg = V4L2_PIX_FMT_JPEG;

std::vector<FormatOffer> webcam() {
  return {{kMjpg, "Motion-JPEG", {SizeRange::discrete(1280, 720), SizeRange::discrete(640, 480)}},
          {kYuyv, "YUYV 4:2:2", {SizeRange::discrete(640, 480), SizeRange::discrete(320, 240)}}};
}

TEST(V4l2Fourcc, NamesAndPixelFormats) {
  EXPECT_EQ(fourccToString(kYuyv), "YUYV");
  EXPECT_EQ(fourccToString(kMjpg), "MJPG");
  EXPECT_EQ(fourccToString(V4L2_PIX_FMT_GREY), "GREY");
  EXPECT_EQ(fourccToString(V4L2_PIX_FMT_Y10), "Y10");  // "Y10 " padded with a space
  EXPECT_EQ(fourccToString(0x00000001u), "0x00000001");
  EXPECT_EQ(fourccToString(V4L2_PIX_FMT_Y16_BE), "Y16-BE");  // big-endian flag on "Y16 "
  EXPECT_EQ(fourccToString(V4L2_PIX_FMT_XRGB555X), "XR15-BE");
  EXPECT_EQ(kFourccYuyv, kYuyv);
  EXPECT_EQ(kFourccMjpeg, kMjpg);
  EXPECT_EQ(pixelFormatOf(kYuyv), PixelFormat::kYuyv);
  EXPECT_EQ(pixelFormatOf(kJpeg), PixelFormat::kMjpeg);
  EXPECT_FALSE(pixelFormatOf(kRgb3));
}

TEST(V4l2Negotiation, ExactFormatAndSize) {
  const auto n = negotiateFormat("/dev/video0", webcam(), {FormatChoice::kYuyv, 640, 480});
  ASSERT_TRUE(n) << n.error().message();
  EXPECT_EQ(n->fourcc, kYuyv);
  EXPECT_EQ(n->pixelFormat, PixelFormat::kYuyv);
  EXPECT_EQ(n->width, 640u);
  EXPECT_EQ(n->height, 480u);
  EXPECT_TRUE(n->sizeExact);
  const auto m = negotiateFormat("/dev/video0", webcam(), {FormatChoice::kMjpeg, 1280, 720});
  ASSERT_TRUE(m);
  EXPECT_EQ(m->fourcc, kMjpg);
  EXPECT_EQ(m->pixelFormat, PixelFormat::kMjpeg);
}

TEST(V4l2Negotiation, AutoPrefersYuyvThenMjpegThenJpeg) {
  EXPECT_EQ(negotiateFormat("d", webcam(), {FormatChoice::kAuto, 640, 480})->fourcc, kYuyv);
  std::vector<FormatOffer> mjpegOnly{{kRgb3, "RGB", {}}, {kMjpg, "MJPEG", {SizeRange::discrete(640, 480)}}};
  EXPECT_EQ(negotiateFormat("d", mjpegOnly, {FormatChoice::kAuto, 640, 480})->fourcc, kMjpg);
  std::vector<FormatOffer> jpegOnly{{kJpeg, "JFIF JPEG", {SizeRange::discrete(640, 480)}}};
  const auto j = negotiateFormat("d", jpegOnly, {FormatChoice::kMjpeg, 640, 480});
  ASSERT_TRUE(j);
  EXPECT_EQ(j->fourcc, kJpeg);
  EXPECT_EQ(j->pixelFormat, PixelFormat::kMjpeg);
}

TEST(V4l2Negotiation, RefusalNamesDeviceWishAndEveryOffer) {
  std::vector<FormatOffer> vividLike{
      {kYuyv, "YUYV", {SizeRange::discrete(320, 180), SizeRange::discrete(640, 480)}},
      {kUyvy, "UYVY", {SizeRange{16, 1920, 2, 16, 1080, 2}}},
      {kRgb3, "RGB3", {}}};
  const auto r = negotiateFormat("/dev/video3", vividLike, {FormatChoice::kMjpeg, 640, 480});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code, std::errc::invalid_argument);
  EXPECT_EQ(r.error().context,
            "camera /dev/video3: wants MJPEG; the device offers YUYV (320x180 640x480), "
            "UYVY (16x16..1920x1080/+2+2), RGB3 (sizes not enumerated)");
  // Formats with the same sizes are named together (vivid offers ~40 alike).
  std::vector<FormatOffer> alike{{kYuyv, "", {SizeRange::discrete(640, 480)}}, {kRgb3, "", {}},
                                 {kUyvy, "", {SizeRange::discrete(640, 480)}}, {V4L2_PIX_FMT_GREY, "", {SizeRange::discrete(640, 480)}}};
  EXPECT_EQ(describeOffers(alike), "YUYV UYVY GREY (640x480), RGB3 (sizes not enumerated)");
  const auto none = negotiateFormat("/dev/video3", {}, {FormatChoice::kAuto, 640, 480});
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().context, "camera /dev/video3: wants YUYV or MJPEG; the device offers none");
}

TEST(V4l2Negotiation, NearestDiscreteSizeWhenNotOffered) {
  const auto n = negotiateFormat("d", webcam(), {FormatChoice::kYuyv, 600, 400});
  ASSERT_TRUE(n);
  EXPECT_EQ(n->width, 640u);
  EXPECT_EQ(n->height, 480u);
  EXPECT_FALSE(n->sizeExact);
  // Equal distance (|dw|+|dh| = 160 either way): the larger image wins.
  const auto tie = negotiateFormat("d", webcam(), {FormatChoice::kYuyv, 480, 360});
  ASSERT_TRUE(tie);
  EXPECT_EQ(tie->width, 640u);
  EXPECT_EQ(tie->height, 480u);
}

TEST(V4l2Negotiation, StepwiseSizesClampAndAlign) {
  const SizeRange r{16, 1920, 8, 16, 1080, 4};
  EXPECT_TRUE(r.contains(640, 480));
  EXPECT_FALSE(r.contains(641, 480));
  EXPECT_FALSE(r.contains(8, 480));
  EXPECT_EQ(r.nearest(641, 481), std::make_pair(640u, 480u));
  EXPECT_EQ(r.nearest(645, 483), std::make_pair(648u, 484u));
  EXPECT_EQ(r.nearest(5000, 5000), std::make_pair(1920u, 1080u));
  // A maximum off the step grid: the largest size on the grid below it.
  const SizeRange odd{16, 1925, 8, 16, 1080, 4};
  EXPECT_EQ(odd.nearest(5000, 10), std::make_pair(1920u, 16u));
}

TEST(V4l2Negotiation, NoSizesEnumeratedKeepsTheRequest) {
  std::vector<FormatOffer> offers{{kYuyv, "YUYV", {}}};
  const auto n = negotiateFormat("d", offers, {FormatChoice::kYuyv, 800, 600});
  ASSERT_TRUE(n);
  EXPECT_EQ(n->width, 800u);
  EXPECT_TRUE(n->sizeExact);
}

TEST(V4l2Interval, DiscreteClosestRate) {
  std::vector<IntervalRange> offers{IntervalRange::discrete({1, 30}), IntervalRange::discrete({1, 15}),
                                    IntervalRange::discrete({1, 5})};
  EXPECT_EQ(chooseInterval(offers, 15), (Fraction{1, 15}));
  EXPECT_EQ(chooseInterval(offers, 25), (Fraction{1, 30}));
  EXPECT_EQ(chooseInterval(offers, 1), (Fraction{1, 5}));
  // 10 fps is 5 away from both 5 and 15: the higher rate wins.
  EXPECT_EQ(chooseInterval(offers, 10), (Fraction{1, 15}));
  EXPECT_FALSE(chooseInterval({}, 15));
  // NTSC-style intervals: 1001/30000 is 29.97 fps.
  std::vector<IntervalRange> ntsc{IntervalRange::discrete({1001, 30000}), IntervalRange::discrete({1001, 15000})};
  EXPECT_EQ(chooseInterval(ntsc, 30), (Fraction{1001, 30000}));
}

TEST(V4l2Interval, StepwiseAndContinuous) {
  // 1/60 .. 1 s in steps of 1/60 s: 15 fps = 4/60 = 1/15.
  const IntervalRange stepwise{{1, 60}, {1, 1}, {1, 60}};
  const auto f = chooseInterval(std::vector{stepwise}, 15);
  ASSERT_TRUE(f);
  EXPECT_DOUBLE_EQ(f->value(), 1.0 / 15);
  EXPECT_EQ(*f, (Fraction{1, 15}));
  // Above the range's fastest rate: clamped to it.
  EXPECT_DOUBLE_EQ(chooseInterval(std::vector{stepwise}, 200)->value(), 1.0 / 60);
  const IntervalRange continuous{{1, 100}, {1, 2}, {}};
  EXPECT_NEAR(chooseInterval(std::vector{continuous}, 15)->value(), 1.0 / 15, 1e-6);
  EXPECT_NEAR(chooseInterval(std::vector{continuous}, 1)->value(), 0.5, 1e-9);
}

// Whatever a (broken) driver enumerates: no crash, and what is chosen is something offered.
TEST(V4l2Negotiation, FuzzedOffersYieldOfferedChoicesOrClearErrors) {
  std::mt19937 rng(21);  // 32-bit results
  auto below = [&](std::uint32_t n) { return static_cast<std::uint32_t>(rng() % n); };
  const std::uint32_t codes[] = {kYuyv, kMjpg, kRgb3, kJpeg, 0};
  auto small = [&] { return static_cast<std::uint32_t>(rng() % 5 == 0 ? rng() : rng() % 4000); };
  for (int i = 0; i < 20000; ++i) {
    std::vector<FormatOffer> offers(rng() % 4);
    for (FormatOffer& f : offers) {
      f.fourcc = codes[rng() % 5];
      f.sizes.resize(rng() % 4);
      for (SizeRange& r : f.sizes)
        r = rng() % 2 ? SizeRange::discrete(small(), small())
                      : SizeRange{small(), small(), below(9), small(), small(), below(9)};
    }
    const CaptureRequest want{static_cast<FormatChoice>(rng() % 3), small(), small()};
    const auto n = negotiateFormat("/dev/videoF", offers, want);
    if (!n) {
      EXPECT_EQ(n.error().context.rfind("camera /dev/videoF: wants ", 0), 0u);
      continue;
    }
    const auto f = std::find_if(offers.begin(), offers.end(), [&](const FormatOffer& o) { return o.fourcc == n->fourcc; });
    ASSERT_NE(f, offers.end());
    const bool anyValid = std::any_of(f->sizes.begin(), f->sizes.end(), [](const SizeRange& r) { return r.valid(); });
    if (!anyValid) {
      EXPECT_EQ(n->width, want.width);  // nothing usable enumerated: the request goes to S_FMT
      continue;
    }
    // The size lies inside an offered range (between its bounds; on its step grid when exact).
    const bool inside = std::any_of(f->sizes.begin(), f->sizes.end(), [&](const SizeRange& r) {
      return r.valid() && n->width >= r.minWidth && n->width <= r.maxWidth && n->height >= r.minHeight && n->height <= r.maxHeight;
    });
    EXPECT_TRUE(inside) << n->width << "x" << n->height;
    EXPECT_EQ(n->sizeExact, n->width == want.width && n->height == want.height);
  }
  for (int i = 0; i < 20000; ++i) {
    std::vector<IntervalRange> offers(rng() % 4);
    for (IntervalRange& r : offers) {
      const Fraction a{small(), small()}, b{small(), small()}, c{below(3), small()};
      r = rng() % 2 ? IntervalRange::discrete(a) : IntervalRange{a, b, c};
    }
    const double fps = 0.5 + rng() % 500;
    const auto f = chooseInterval(offers, fps);
    const bool anyValid = std::any_of(offers.begin(), offers.end(), [](const IntervalRange& r) { return r.valid(); });
    ASSERT_EQ(f.has_value(), anyValid);
    if (!f) continue;
    EXPECT_TRUE(f->valid());
    const bool inside = std::any_of(offers.begin(), offers.end(), [&](const IntervalRange& r) {
      return r.valid() && f->value() >= r.min.value() * (1 - 1e-9) && f->value() <= (r.isDiscrete() ? r.min : r.max).value() * (1 + 1e-9);
    });
    EXPECT_TRUE(inside) << f->numerator << "/" << f->denominator;
  }
}

TEST(V4l2Format, ParseChoice) {
  EXPECT_EQ(parseFormatChoice("yuyv"), FormatChoice::kYuyv);
  EXPECT_EQ(parseFormatChoice("mjpeg"), FormatChoice::kMjpeg);
  EXPECT_EQ(parseFormatChoice("auto"), FormatChoice::kAuto);
  EXPECT_FALSE(parseFormatChoice("YUYV"));
  EXPECT_FALSE(parseFormatChoice(""));
}

TEST(V4l2Controls, ParseSetting) {
  EXPECT_TRUE(parseControlSetting("auto")->automatic);
  const auto fixed = parseControlSetting("10000");
  ASSERT_TRUE(fixed);
  EXPECT_FALSE(fixed->automatic);
  EXPECT_EQ(fixed->value, 10000);
  EXPECT_EQ(parseControlSetting("0")->value, 0);
  EXPECT_EQ(parseControlSetting("2147483647")->value, 2147483647);
  for (const char* bad : {"", "-1", "+5", "1e3", "10 ", "Auto", "2147483648", "99999999999", "0x10"})
    EXPECT_FALSE(parseControlSetting(bad)) << bad;
}

TEST(V4l2Buffers, GrantedCountChecked) {
  EXPECT_TRUE(checkGrantedBuffers("/dev/video0", 4, 4));
  EXPECT_TRUE(checkGrantedBuffers("/dev/video0", 4, 6));
  const auto r = checkGrantedBuffers("/dev/video0", 6, 3);
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().context,
            "camera /dev/video0: asked for 6 capture buffers, the device granted 3 (need at least 4)");
  EXPECT_FALSE(checkGrantedBuffers("/dev/video0", 4, 0));
}

TEST(V4l2Buffers, QueueDequeueBookkeeping) {
  BufferRing ring;
  ring.reset(4);
  for (std::uint32_t i = 0; i < 4; ++i) ring.setLength(i, 1000);
  EXPECT_EQ(ring.queued(), 0u);
  for (std::uint32_t i = 0; i < 4; ++i) ASSERT_TRUE(ring.markQueued(i));
  EXPECT_EQ(ring.queued(), 4u);
  EXPECT_FALSE(ring.markQueued(2));  // twice
  EXPECT_FALSE(ring.markQueued(4));  // no such buffer
  ASSERT_TRUE(ring.markDequeued(2, 1000));
  EXPECT_FALSE(ring.isQueued(2));
  EXPECT_EQ(ring.queued(), 3u);
  const auto twice = ring.markDequeued(2, 10);
  ASSERT_FALSE(twice);
  EXPECT_EQ(twice.error().context, "the driver returned buffer 2, which was not queued");
  const auto unknown = ring.markDequeued(7, 10);
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().context, "the driver returned buffer 7 of 4");
  const auto overfull = ring.markDequeued(1, 1001);
  ASSERT_FALSE(overfull);
  EXPECT_EQ(overfull.error().context, "buffer 1 reports 1001 bytes used of 1000");
  EXPECT_TRUE(ring.isQueued(1));  // a refused answer changes nothing
  EXPECT_EQ(ring.queued(), 3u);
  ring.markAllDequeued();
  EXPECT_EQ(ring.queued(), 0u);
  EXPECT_TRUE(ring.markQueued(1));
}

TEST(V4l2Buffers, RandomOperationsKeepTheCountConsistent) {
  std::mt19937 rng(12);
  BufferRing ring;
  ring.reset(6);
  for (std::uint32_t i = 0; i < 6; ++i) ring.setLength(i, 64);
  std::vector<bool> model(6, false);
  for (int step = 0; step < 5000; ++step) {
    const std::uint32_t i = rng() % 8;  // sometimes out of range
    if (rng() % 2) {
      const bool ok = static_cast<bool>(ring.markQueued(i));
      EXPECT_EQ(ok, i < 6 && !model[i]);
      if (ok) model[i] = true;
    } else {
      const std::uint32_t used = rng() % 80;
      const bool ok = static_cast<bool>(ring.markDequeued(i, used));
      EXPECT_EQ(ok, i < 6 && model[i] && used <= 64);
      if (ok) model[i] = false;
    }
    EXPECT_EQ(ring.queued(), static_cast<std::uint32_t>(std::count(model.begin(), model.end(), true)));
  }
}

TEST(V4l2Sequence, GapsLossesAndResets) {
  SequenceTracker t;
  EXPECT_EQ(t.next(100).lost, 0u);  // the first frame after a start is the reference
  EXPECT_EQ(t.next(101).lost, 0u);
  EXPECT_EQ(t.next(104).lost, 2u);
  EXPECT_EQ(t.next(105).lost, 0u);
  EXPECT_EQ(t.next(115).lost, 9u);
  EXPECT_EQ(t.gaps(), 2u);
  EXPECT_EQ(t.lost(), 11u);
  const auto back = t.next(3);
  EXPECT_TRUE(back.reset);
  EXPECT_EQ(back.lost, 0u);
  EXPECT_TRUE(t.next(3).reset);  // a repeat
  EXPECT_EQ(t.resets(), 2u);
  EXPECT_EQ(t.next(4).lost, 0u);
  // A restart is not a reset: counting starts again without a gap.
  t.restart();
  EXPECT_EQ(t.next(0).lost, 0u);
  EXPECT_EQ(t.resets(), 2u);
  EXPECT_EQ(t.lost(), 11u);
}

TEST(V4l2Sequence, WrapAroundIsOneStep) {
  SequenceTracker t;
  (void)t.next(0xFFFFFFFEu);
  EXPECT_EQ(t.next(0xFFFFFFFFu).lost, 0u);
  EXPECT_EQ(t.next(0u).lost, 0u);
  EXPECT_EQ(t.next(2u).lost, 1u);
  EXPECT_EQ(t.resets(), 0u);
  EXPECT_EQ(t.lost(), 1u);
}

TEST(V4l2Sequence, AgreesWithAFrameByFrameModel) {
  std::mt19937 rng(7);
  SequenceTracker t;
  std::uint32_t seq = 0xFFFFFF00u;  // crosses the wrap
  std::uint64_t dropped = 0;
  (void)t.next(seq);
  for (int i = 0; i < 20000; ++i) {
    std::uint32_t skip = rng() % 10 == 0 ? 1 + rng() % 5 : 0;
    dropped += skip;
    seq += 1 + skip;
    (void)t.next(seq);
  }
  EXPECT_EQ(t.lost(), dropped);
  EXPECT_EQ(t.resets(), 0u);
}

TEST(V4l2Stall, RestartsThenReopens) {
  using namespace std::chrono_literals;
  const auto t0 = StallPolicy::Clock::time_point{} + 100s;
  StallPolicy p(500ms, 2);
  p.streamStarted(t0);
  EXPECT_EQ(p.check(t0 + 499ms), StallAction::kNone);
  EXPECT_EQ(p.check(t0 + 500ms), StallAction::kRestartStream);
  EXPECT_EQ(p.check(t0 + 900ms), StallAction::kNone);  // a full limit after the action
  EXPECT_EQ(p.check(t0 + 1000ms), StallAction::kRestartStream);
  EXPECT_EQ(p.check(t0 + 1500ms), StallAction::kReopen);
  EXPECT_EQ(p.stalls(), 3u);
  // After the reopen the escalation starts again.
  p.streamStarted(t0 + 2s);
  EXPECT_EQ(p.check(t0 + 2500ms), StallAction::kRestartStream);
  // A frame clears the escalation.
  p.frameArrived(t0 + 2600ms);
  EXPECT_EQ(p.restartsInARow(), 0);
  EXPECT_EQ(p.check(t0 + 3000ms), StallAction::kNone);
  EXPECT_EQ(p.check(t0 + 3100ms), StallAction::kRestartStream);
  StallPolicy never(500ms, 0);  // no restarts allowed: straight to reopen
  never.streamStarted(t0);
  EXPECT_EQ(never.check(t0 + 600ms), StallAction::kReopen);
}

ControlInfo menu(std::vector<std::int32_t> items) {
  ControlInfo c;
  c.minimum = 0;
  c.maximum = 3;
  c.menuItems = std::move(items);
  return c;
}
ControlInfo range(std::int32_t lo, std::int32_t hi, std::int32_t step) {
  ControlInfo c;
  c.minimum = lo;
  c.maximum = hi;
  c.step = step;
  return c;
}

TEST(V4l2Controls, AutoOnAUvcCameraUsesAperturePriority) {
  // UVC: exposure_auto menu has manual (1) and aperture priority (3) only.
  const std::map<std::uint32_t, ControlInfo> uvc{{V4L2_CID_EXPOSURE_AUTO, menu({1, 3})},
                                                 {V4L2_CID_EXPOSURE_ABSOLUTE, range(3, 2047, 1)},
                                                 {V4L2_CID_GAIN, range(0, 255, 1)}};
  const ControlPlan p = planControls({}, uvc);
  ASSERT_EQ(p.writes.size(), 1u);
  EXPECT_EQ(p.writes[0].id, static_cast<std::uint32_t>(V4L2_CID_EXPOSURE_AUTO));
  EXPECT_EQ(p.writes[0].value, 3);
  ASSERT_EQ(p.notes.size(), 1u);
  EXPECT_EQ(p.notes[0], "gain: the device has no automatic gain control; it keeps its own setting");
}

TEST(V4l2Controls, FixedValuesInOrderWithClamping) {
  const std::map<std::uint32_t, ControlInfo> cam{{V4L2_CID_EXPOSURE_AUTO, menu({0, 1, 3})},
                                                 {V4L2_CID_EXPOSURE_ABSOLUTE, range(1, 5000, 1)},
                                                 {V4L2_CID_AUTOGAIN, range(0, 1, 1)},
                                                 {V4L2_CID_GAIN, range(0, 100, 4)}};
  ControlsConfig c;
  c.exposure = {false, 8000};  // 8 ms = 80 units of 100 us
  c.gain = {false, 150};
  const ControlPlan p = planControls(c, cam);
  ASSERT_EQ(p.writes.size(), 4u);
  EXPECT_EQ(p.writes[0].id, static_cast<std::uint32_t>(V4L2_CID_EXPOSURE_AUTO));
  EXPECT_EQ(p.writes[0].value, V4L2_EXPOSURE_MANUAL);
  EXPECT_EQ(p.writes[1].id, static_cast<std::uint32_t>(V4L2_CID_EXPOSURE_ABSOLUTE));
  EXPECT_EQ(p.writes[1].value, 80);
  EXPECT_EQ(p.writes[2].id, static_cast<std::uint32_t>(V4L2_CID_AUTOGAIN));
  EXPECT_EQ(p.writes[2].value, 0);
  EXPECT_EQ(p.writes[3].id, static_cast<std::uint32_t>(V4L2_CID_GAIN));
  EXPECT_EQ(p.writes[3].value, 100);
  ASSERT_EQ(p.notes.size(), 1u);
  EXPECT_EQ(p.notes[0], "gain 150 is not available; using 100 (range 0..100, step 4)");
  // Step rounding: 50 -> 52 (0, 4, ..., 48, 52).
  c.gain = {false, 50};
  EXPECT_EQ(planControls(c, cam).writes[3].value, 52);
  // Fully automatic on this camera: exposure mode "auto" (0) is offered.
  const ControlPlan a = planControls({}, cam);
  ASSERT_EQ(a.writes.size(), 2u);
  EXPECT_EQ(a.writes[0].value, V4L2_EXPOSURE_AUTO);
  EXPECT_EQ(a.writes[1].id, static_cast<std::uint32_t>(V4L2_CID_AUTOGAIN));
  EXPECT_EQ(a.writes[1].value, 1);
  EXPECT_TRUE(a.notes.empty());
}

TEST(V4l2Controls, MissingOrReadOnlyControlsAreNotedNotWritten) {
  ControlsConfig c;
  c.exposure = {false, 10000};
  c.gain = {false, 3};
  const ControlPlan none = planControls(c, {});
  EXPECT_TRUE(none.writes.empty());
  ASSERT_EQ(none.notes.size(), 2u);
  EXPECT_EQ(none.notes[0], "exposure: the device has no absolute exposure control; fixed exposure 10000 us not applied");
  EXPECT_EQ(none.notes[1], "gain: the device has no gain control; fixed gain 3 not applied");
  ControlInfo ro = range(0, 10, 1);
  ro.writable = false;
  const ControlPlan p = planControls(c, {{V4L2_CID_GAIN, ro}});
  EXPECT_TRUE(p.writes.empty());
  // A camera whose exposure menu lacks manual cannot take a fixed exposure.
  const ControlPlan noManual = planControls(c, {{V4L2_CID_EXPOSURE_AUTO, menu({3})}, {V4L2_CID_EXPOSURE_ABSOLUTE, range(1, 10, 1)}});
  EXPECT_TRUE(noManual.writes.empty());
  EXPECT_EQ(noManual.notes[0], "exposure: the device offers no manual exposure mode; fixed exposure not applied");
}

}  // namespace
