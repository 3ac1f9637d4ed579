// SPDX-License-Identifier: Apache-2.0
// Camera frame decoding, frame pairing, camera layers (hue, hue distance across the wrap).

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "fusedet/core/hue_distance.h"
#include "fusedet/fusion/camera_layers.h"
#include "fusedet/fusion/frame_decode.h"
#include "fusedet/fusion/pairing.h"

using namespace fusedet;
using namespace fusedet::fusion;
using drivers::CameraFrame;
using drivers::PixelFormat;

namespace {
CameraFrame frameOf(PixelFormat f, int w, int h, std::vector<std::uint8_t> bytes, int stride = 0) {
  CameraFrame c;
  c.sequence = 7;
  c.width = w;
  c.height = h;
  c.stride = stride;
  c.format = f;
  c.bytes = std::move(bytes);
  return c;
}
}  // namespace

TEST(FrameDecode, Bgr24WithPaddedStrideAndGray8) {
  // 2x2 BGR with 2 padding bytes per row.
  const auto bgr = decodeCameraFrame(frameOf(PixelFormat::kBgr24, 2, 2, {1, 2, 3, 4, 5, 6, 0, 0, 7, 8, 9, 10, 11, 12, 0, 0}, 8));
  ASSERT_TRUE(bgr) << bgr.error().message();
  EXPECT_EQ(bgr->at<cv::Vec3b>(1, 1), cv::Vec3b(10, 11, 12));
  const auto gray = decodeCameraFrame(frameOf(PixelFormat::kGray8, 3, 1, {0, 128, 255}));
  ASSERT_TRUE(gray);
  EXPECT_EQ(gray->at<cv::Vec3b>(0, 1), cv::Vec3b(128, 128, 128));
}

TEST(FrameDecode, YuyvFollowsBt601) {
  // Y0 U Y1 V: two pixels sharing chroma. Y 81, U 90, V 240 is BT.601 red (R 255, G 0, B 0).
  const auto img = decodeCameraFrame(frameOf(PixelFormat::kYuyv, 2, 1, {81, 90, 81, 240}));
  ASSERT_TRUE(img);
  for (int x = 0; x < 2; ++x) {
    const cv::Vec3b p = img->at<cv::Vec3b>(0, x);
    EXPECT_NEAR(p[2], 255, 3);
    EXPECT_NEAR(p[1], 0, 3);
    EXPECT_NEAR(p[0], 0, 3);
  }
  // Neutral chroma (128): grey at the video-range luma, R = G = B = 1.164 (Y - 16).
  const auto grey = decodeCameraFrame(frameOf(PixelFormat::kYuyv, 2, 1, {126, 128, 126, 128}));
  ASSERT_TRUE(grey);
  EXPECT_NEAR(grey->at<cv::Vec3b>(0, 0)[1], 1.164 * (126 - 16), 2);
  EXPECT_FALSE(decodeCameraFrame(frameOf(PixelFormat::kYuyv, 3, 1, std::vector<std::uint8_t>(6))));
}

TEST(FrameDecode, MjpegRoundTripAndErrors) {
  cv::Mat src(48, 64, CV_8UC3, cv::Scalar(20, 140, 230));
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", src, jpeg, {cv::IMWRITE_JPEG_QUALITY, 95});
  const auto img = decodeCameraFrame(frameOf(PixelFormat::kMjpeg, 64, 48, jpeg));
  ASSERT_TRUE(img);
  EXPECT_LT(cv::norm(*img, src, cv::NORM_INF), 4);
  const auto wrongSize = decodeCameraFrame(frameOf(PixelFormat::kMjpeg, 640, 480, jpeg));
  ASSERT_FALSE(wrongSize);
  EXPECT_NE(wrongSize.error().message().find("64x48"), std::string::npos);
  EXPECT_NE(wrongSize.error().message().find("camera frame 7"), std::string::npos);
  const auto truncated = decodeCameraFrame(frameOf(PixelFormat::kMjpeg, 64, 48, {jpeg.begin(), jpeg.begin() + 40}));
  EXPECT_FALSE(truncated);
  const auto shortBgr = decodeCameraFrame(frameOf(PixelFormat::kBgr24, 4, 4, std::vector<std::uint8_t>(47)));
  ASSERT_FALSE(shortBgr);
  EXPECT_NE(shortBgr.error().message().find("need 48"), std::string::npos);
  EXPECT_FALSE(decodeCameraFrame(frameOf(PixelFormat::kBgr24, 4, 4, std::vector<std::uint8_t>(48), 5)));
  EXPECT_FALSE(decodeCameraFrame(frameOf(PixelFormat::kBgr24, 0, 4, {})));
}

TEST(FrameDecode, FuzzedFramesNeverCrash) {
  cv::Mat src(32, 48, CV_8UC3);
  cv::randu(src, 0, 255);
  std::vector<std::uint8_t> jpeg;
  cv::imencode(".jpg", src, jpeg);
  std::mt19937 rng(5);
  int failures = 0;
  for (int iter = 0; iter < 300; ++iter) {
    std::vector<std::uint8_t> b = jpeg;
    for (int k = 0; k < 1 + static_cast<int>(rng() % 10); ++k) b[rng() % b.size()] = static_cast<std::uint8_t>(rng());
    if (rng() % 3 == 0) b.resize(rng() % b.size());
    const PixelFormat f = static_cast<PixelFormat>(rng() % 4);
    const int w = static_cast<int>(rng() % 80), h = static_cast<int>(rng() % 60);
    const auto r = decodeCameraFrame(frameOf(f, w, h, b, static_cast<int>(rng() % 300) - 20));
    if (!r) ++failures;
    else EXPECT_EQ(r->size(), cv::Size(w, h));
  }
  EXPECT_GT(failures, 100);
}

TEST(FramePairer, PicksTheFrameNearestTheSweepMiddleWithinTheSkew) {
  FramePairer pairer(50'000'000, 8);
  for (int i = 0; i < 6; ++i) {
    CameraFrame f;
    f.sequence = static_cast<std::uint64_t>(i);
    f.stamp = Stamp{1'000'000'000 + i * 66'000'000};  // 15 fps
    pairer.addFrame(f);
  }
  fusion::Sweep s;
  s.start = Stamp{1'000'000'000};
  s.end = Stamp{1'300'000'000};  // middle 1.15 s: frame 2 (1.132 s) is 18 ms away, frame 3 48 ms
  const auto f = pairer.pair(s);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->sequence, 2u);
  EXPECT_EQ(pairer.buffered(), 3u);  // older frames went with it
  s.start = Stamp{5'000'000'000};
  s.end = Stamp{5'100'000'000};
  EXPECT_FALSE(pairer.pair(s));
  EXPECT_EQ(pairer.unpaired(), 1u);
  for (int i = 0; i < 10; ++i) pairer.addFrame(CameraFrame{});
  EXPECT_EQ(pairer.buffered(), 8u);
  EXPECT_EQ(pairer.framesDropped(), 5u);
}

// Issue 37: 32 buffered 1080p frames are 200 MB; the pairer also keeps its frames' bytes under
// a budget (the newest frame always stays), and bytes leave with paired frames.
TEST(FramePairer, KeepsItsFramesUnderAByteBudget) {
  constexpr std::size_t kFrame = 1920 * 1080 * 2;
  FramePairer pairer(50'000'000, 32, 3 * kFrame);
  for (int i = 0; i < 10; ++i) {
    CameraFrame f;
    f.sequence = static_cast<std::uint64_t>(i);
    f.stamp = Stamp{1'000'000'000 + i * 66'000'000};
    f.bytes.assign(kFrame, 0);
    pairer.addFrame(std::move(f));
  }
  EXPECT_EQ(pairer.buffered(), 3u);
  EXPECT_EQ(pairer.bufferedBytes(), 3 * kFrame);
  EXPECT_EQ(pairer.framesDropped(), 7u);
  fusion::Sweep s;
  s.start = Stamp{1'400'000'000};
  s.end = Stamp{1'600'000'000};  // middle 1.5 s: frame 8 (1.528 s)
  const auto f = pairer.pair(s);
  ASSERT_TRUE(f);
  EXPECT_EQ(f->sequence, 8u);
  EXPECT_EQ(pairer.buffered(), 1u);
  EXPECT_EQ(pairer.bufferedBytes(), kFrame);
  CameraFrame huge;
  huge.bytes.assign(4 * kFrame, 0);
  pairer.addFrame(std::move(huge));
  EXPECT_EQ(pairer.buffered(), 1u);
  EXPECT_EQ(pairer.bufferedBytes(), 4 * kFrame);
}

TEST(CameraLayers, HueMatchesOpenCvFloatHsv) {
  cv::Mat bgr(60, 80, CV_8UC3);
  cv::randu(bgr, 0, 256);
  bgr.at<cv::Vec3b>(0, 0) = cv::Vec3b(9, 9, 9);  // grey
  cv::Mat f, hsv;
  bgr.convertTo(f, CV_32F, 1.0 / 255);
  cv::cvtColor(f, hsv, cv::COLOR_BGR2HSV);
  cv::Mat ref;
  cv::extractChannel(hsv, ref, 0);
  const cv::Mat hue = hueDegrees(bgr);
  // OpenCV may return exactly 360 where we wrap to 0; compare on the circle.
  double worst = 0;
  for (int y = 0; y < hue.rows; ++y)
    for (int x = 0; x < hue.cols; ++x) {
      worst = std::max(worst, hueDistanceDeg(hue.at<float>(y, x), ref.at<float>(y, x)));
      EXPECT_LT(hue.at<float>(y, x), 360.f);
      EXPECT_GE(hue.at<float>(y, x), 0.f);
    }
  EXPECT_LT(worst, 1e-3);
  EXPECT_EQ(hue.at<float>(0, 0), 0.f);
}

TEST(CameraLayers, StackHasFiveCameraLayersAndHueDistanceWrapsAtZero) {
  // Two reds either side of 0 deg: hue 350 (R 255, G 0, B 42.5) and hue 10 (R 255, G 42.5, B 0).
  cv::Mat bgr(1, 3, CV_8UC3);
  bgr.at<cv::Vec3b>(0, 0) = cv::Vec3b(43, 0, 255);   // hue 360 - 60 * 43/255 = 349.88
  bgr.at<cv::Vec3b>(0, 1) = cv::Vec3b(0, 43, 255);   // hue 60 * 43/255 = 10.12
  bgr.at<cv::Vec3b>(0, 2) = cv::Vec3b(255, 255, 0);  // cyan: 180
  LayerStack s;
  addCameraLayers(s, bgr);
  EXPECT_EQ(s.names(), (std::vector<std::string>{"red", "green", "blue", "intensity", "hue"}));
  EXPECT_EQ(s.width(), 3);
  EXPECT_EQ(s.at("red").data.at<std::uint8_t>(0, 0), 255);
  EXPECT_EQ(s.at("blue").data.at<std::uint8_t>(0, 0), 43);
  EXPECT_EQ(s.at("intensity").data.at<std::uint8_t>(0, 2), std::lround(0.587 * 255 + 0.114 * 255));
  const cv::Mat& hue = s.at("hue").data;
  EXPECT_NEAR(hue.at<float>(0, 0), 360 - 60.0 * 43 / 255, 1e-3);
  EXPECT_NEAR(hue.at<float>(0, 1), 60.0 * 43 / 255, 1e-3);
  const cv::Mat d = hueDistanceLayer(hue, 0.0);  // reference red: both reds ~10 deg away
  EXPECT_NEAR(d.at<float>(0, 0), 60.0 * 43 / 255, 1e-3);
  EXPECT_NEAR(d.at<float>(0, 1), 60.0 * 43 / 255, 1e-3);
  EXPECT_NEAR(d.at<float>(0, 2), 180, 1e-3);
  const cv::Mat d355 = hueDistanceLayer(hue, 355.0);
  EXPECT_NEAR(d355.at<float>(0, 1), 5 + 60.0 * 43 / 255, 1e-3);  // across the wrap
}
