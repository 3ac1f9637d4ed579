// SPDX-License-Identifier: Apache-2.0
// The cv::dnn runner and decoder (fusion/neural): SHA-256 against FIPS 180-4's examples and the
// shared models' SHA256SUMS, the letterbox and resize geometry and the decoding of hand-written
// output rows against numbers worked out by hand, clear errors (missing file, wrong kind, refused
// input size), and the same output bytes on every run of both networks on a KITTI frame.

#include <gtest/gtest.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <opencv2/imgcodecs.hpp>
#include <string>

#include "fusedet/fusion/neural/anchors.h"
#include "fusedet/fusion/neural/input_geometry.h"
#include "fusedet/fusion/neural/network.h"
#include "fusedet/fusion/neural/sha256.h"

namespace fusedet::fusion {
namespace {
namespace fs = std::filesystem;

const fs::path kModels = FUSEDET_NETWORKS_DIR;
const fs::path kFrame = fs::path(FUSEDET_DATA_DIR) / "kitti/image_2/000000.png";

NetworkSpec yolov5Spec() { return {NetworkKind::yolov5Onnx, {kModels / "yolov5n_256x832.onnx"}, {832, 256}, 1}; }
NetworkSpec darknetSpec() {
  return {NetworkKind::darknet, {kModels / "yolo-fastest-1.1-xl.cfg", kModels / "yolo-fastest-1.1-xl.weights"}, {832, 256}, 1};
}

std::string sha(const std::string& s) {
  return sha256Hex({reinterpret_cast<const unsigned char*>(s.data()), s.size()});
}

std::string loadError(const NetworkSpec& spec) {
  try {
    Network n(spec);
  } catch (const std::exception& e) {
    return e.what();
  }
  return "(loaded)";
}

TEST(Sha256, FipsExamples) {
  EXPECT_EQ(sha(""), "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855");
  EXPECT_EQ(sha("abc"), "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad");
  EXPECT_EQ(sha("abcdbcdecdefdefgefghfghighijhijkijkljklmklmnlmnomnopnopq"),
            "248d6a61d20638b8e5c026930c3e6039a33ce45964ff2167f6ecedd419db06c1");
  EXPECT_EQ(sha(std::string(1000000, 'a')), "cdc76e5c9914fb9281a1c7e284d73e67f1809a48a497200e046d39ccc7112cd0");
}

TEST(Sha256, SharedModelsMatchTheirChecksumFile) {
  std::ifstream sums(kModels / "SHA256SUMS");
  ASSERT_TRUE(sums) << kModels;
  std::string digest, name;
  int n = 0;
  while (sums >> digest >> name) {
    EXPECT_EQ(sha256File(kModels / name), digest) << name;
    ++n;
  }
  EXPECT_EQ(n, 4);
  EXPECT_THROW(sha256File(kModels / "no-such-file"), std::runtime_error);
}

TEST(InputGeometry, LetterboxOfAKittiFrameWorkedByHand) {
  // r = min(832 / 1242, 256 / 375) = 832 / 1242; scaled 832 x round(375 * 832 / 1242 = 251.2) = 251;
  // pad top (256 - 251) / 2 = 2.
  const InputGeometry g = letterboxGeometry({1242, 375}, {832, 256});
  EXPECT_DOUBLE_EQ(g.scaleX, 832.0 / 1242.0);
  EXPECT_DOUBLE_EQ(g.scaleY, 832.0 / 1242.0);
  EXPECT_EQ(g.padX, 0);
  EXPECT_EQ(g.padY, 2);
  cv::Mat bgr(375, 1242, CV_8UC3, cv::Scalar(10, 20, 30));
  const cv::Mat in = makeInputImage(bgr, g);
  ASSERT_EQ(in.size(), cv::Size(832, 256));
  EXPECT_EQ(in.at<cv::Vec3b>(1, 400), cv::Vec3b(114, 114, 114));    // above the image
  EXPECT_EQ(in.at<cv::Vec3b>(2, 400), cv::Vec3b(10, 20, 30));       // first image row
  EXPECT_EQ(in.at<cv::Vec3b>(252, 400), cv::Vec3b(10, 20, 30));     // last image row (2 + 251 - 1)
  EXPECT_EQ(in.at<cv::Vec3b>(253, 400), cv::Vec3b(114, 114, 114));  // below it
  // A tall image pads left and right: r = 256 / 512, scaled 100 x 256, pad (832 - 100) / 2 = 366.
  const InputGeometry t = letterboxGeometry({200, 512}, {832, 256});
  EXPECT_EQ(t.padX, 366);
  EXPECT_EQ(t.padY, 0);
}

TEST(InputGeometry, ResizeStretchesEachAxis) {
  const InputGeometry g = resizeGeometry({1242, 375}, {832, 256});
  EXPECT_DOUBLE_EQ(g.scaleX, 832.0 / 1242.0);
  EXPECT_DOUBLE_EQ(g.scaleY, 256.0 / 375.0);
  EXPECT_EQ(g.padX, 0);
  EXPECT_EQ(g.padY, 0);
  EXPECT_THROW(resizeGeometry({0, 375}, {832, 256}), std::invalid_argument);
}

TEST(Decode, Yolov5RowsWorkedByHand) {
  // Two rows of a 3-class network: cx, cy, w, h (input pixels), objectness, class probabilities.
  const int sizes[] = {1, 2, 8};
  cv::Mat out(3, sizes, CV_32F);
  const float rows[2][8] = {{100, 50, 40, 20, 0.5f, 0.2f, 0.8f, 0.1f}, {416, 130, 832, 252, 1.0f, 0.0f, 0.25f, 1.0f}};
  std::memcpy(out.data, rows, sizeof rows);
  const Anchors a = decodeYolov5(out, letterboxGeometry({1242, 375}, {832, 256}));
  ASSERT_EQ(a.size(), 2u);
  ASSERT_EQ(a.classes(), 3);
  // Row 0: left 100 - 20 = 80 -> 80 * 1242 / 832 = 119.4231; top 50 - 10 - pad 2 = 38 -> 56.7260;
  // 40 -> 59.7115, 20 -> 29.8558.
  EXPECT_NEAR(a.boxes[0].x, 119.4230769, 1e-4);
  EXPECT_NEAR(a.boxes[0].y, 56.7259615, 1e-4);
  EXPECT_NEAR(a.boxes[0].w, 59.7115385, 1e-4);
  EXPECT_NEAR(a.boxes[0].h, 29.8557692, 1e-4);
  EXPECT_FLOAT_EQ(a.scores.at<float>(0, 0), 0.1f);  // 0.5 x 0.2
  EXPECT_FLOAT_EQ(a.scores.at<float>(0, 1), 0.4f);  // 0.5 x 0.8
  EXPECT_FLOAT_EQ(a.scores.at<float>(0, 2), 0.05f);
  EXPECT_FLOAT_EQ(a.objectness[0], 0.5f);
  // Row 1 covers the whole letterboxed image: 0, (4 - 2) -> 2.986, 1242 wide, 252 -> 376.1827.
  EXPECT_NEAR(a.boxes[1].x, 0.0, 1e-9);
  EXPECT_NEAR(a.boxes[1].y, 2 * 1242.0 / 832.0, 1e-4);
  EXPECT_NEAR(a.boxes[1].w, 1242.0, 1e-4);
  EXPECT_NEAR(a.boxes[1].h, 376.1826923, 1e-4);
  EXPECT_FLOAT_EQ(a.scores.at<float>(1, 1), 0.25f);
}

TEST(Decode, DarknetRowsOfTwoLayersWorkedByHand) {
  // Normalised cx, cy, w, h, objectness, 2 class scores that already include the objectness.
  cv::Mat first = (cv::Mat_<float>(1, 7) << 0.5f, 0.5f, 0.1f, 0.2f, 0.9f, 0.0f, 0.6f);
  cv::Mat second = (cv::Mat_<float>(2, 7) << 0.25f, 0.75f, 0.5f, 0.5f, 0.3f, 0.3f, 0.0f,  //
                    0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f, 0.0f);
  const Anchors a = decodeDarknet({first, second}, resizeGeometry({1242, 375}, {832, 256}));
  ASSERT_EQ(a.size(), 3u);
  // (0.5 - 0.05) * 1242 = 558.9, (0.5 - 0.1) * 375 = 150, 0.1 * 1242 = 124.2, 0.2 * 375 = 75.
  EXPECT_NEAR(a.boxes[0].x, 558.9, 1e-3);
  EXPECT_NEAR(a.boxes[0].y, 150.0, 1e-3);
  EXPECT_NEAR(a.boxes[0].w, 124.2, 1e-3);
  EXPECT_NEAR(a.boxes[0].h, 75.0, 1e-3);
  EXPECT_FLOAT_EQ(a.scores.at<float>(0, 1), 0.6f);  // taken as it is, not times 0.9
  // (0.25 - 0.25) * 1242 = 0, (0.75 - 0.25) * 375 = 187.5.
  EXPECT_NEAR(a.boxes[1].x, 0.0, 1e-3);
  EXPECT_NEAR(a.boxes[1].y, 187.5, 1e-3);
  EXPECT_FLOAT_EQ(a.scores.at<float>(1, 0), 0.3f);
  EXPECT_THROW(decodeDarknet({cv::Mat_<float>(2, 4)}, resizeGeometry({10, 10}, {32, 32})), std::invalid_argument);
}

TEST(Network, MissingFileIsNamed) {
  NetworkSpec s = yolov5Spec();
  s.files = {kModels / "absent.onnx"};
  const std::string e = loadError(s);
  EXPECT_NE(e.find("absent.onnx"), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;
}

TEST(Network, WrongKindIsNamed) {
  NetworkSpec s = yolov5Spec();
  s.files = {kModels / "yolo-fastest-1.1-xl.cfg"};  // a Darknet cfg given as yolov5-onnx
  std::string e = loadError(s);
  EXPECT_NE(e.find("yolo-fastest-1.1-xl.cfg: a Darknet cfg, not an ONNX file"), std::string::npos) << e;
  NetworkSpec d = darknetSpec();
  d.files = {kModels / "yolov5n_256x832.onnx", kModels / "yolo-fastest-1.1-xl.weights"};  // ONNX as the cfg
  e = loadError(d);
  EXPECT_NE(e.find("yolov5n_256x832.onnx: not a Darknet cfg"), std::string::npos) << e;
  d.files = {kModels / "yolo-fastest-1.1-xl.cfg"};  // weights missing
  e = loadError(d);
  EXPECT_NE(e.find("expected a cfg and a weights file, got 1"), std::string::npos) << e;
  EXPECT_THROW(parseNetworkKind("onnx"), std::invalid_argument);
  EXPECT_EQ(parseNetworkKind("darknet"), NetworkKind::darknet);
}

TEST(Network, RefusedInputSizeIsNamed) {
  NetworkSpec s = yolov5Spec();
  s.input = {640, 256};  // the file was exported for 832 x 256
  std::string e = loadError(s);
  EXPECT_NE(e.find("yolov5n_256x832.onnx: the network refuses input size 640x256"), std::string::npos) << e;
  NetworkSpec d = darknetSpec();
  d.input = {830, 250};
  e = loadError(d);
  EXPECT_NE(e.find("yolo-fastest-1.1-xl.cfg: Darknet input size 830x250 is not a multiple of 32"), std::string::npos) << e;
}

TEST(Network, IdentityNamesKindSizeAndDigests) {
  Network n(darknetSpec());
  const NetworkIdentity& id = n.identity();
  EXPECT_EQ(id.kind, NetworkKind::darknet);
  EXPECT_EQ(id.input, cv::Size(832, 256));
  ASSERT_EQ(id.sha256.size(), 2u);
  EXPECT_EQ(id.sha256[0], "c458427acc4fbeabceff4528ef7b65b066c0308ce599460f8ba299eba63abad3");  // SHA256SUMS
  EXPECT_EQ(id.sha256[1], "fac5fb41786c1f38f04972a658443b189f48720d7d117f9a044100e98a35b0c5");
  EXPECT_EQ(id.text().rfind("darknet 832x256 yolo-fastest-1.1-xl.cfg sha256:c458427a", 0), 0u) << id.text();
}

// Same output bytes from two runs of one network and from a second network loaded from the same files.
void expectSameBytes(const NetworkSpec& spec, std::size_t expectRows) {
  const cv::Mat bgr = cv::imread(kFrame.string());
  ASSERT_FALSE(bgr.empty()) << kFrame;
  Network first(spec), second(spec);
  const NetworkOutput one = first.forward(bgr), again = first.forward(bgr), other = second.forward(bgr);
  ASSERT_EQ(one.outputs.size(), again.outputs.size());
  ASSERT_EQ(one.outputs.size(), other.outputs.size());
  for (std::size_t i = 0; i < one.outputs.size(); ++i) {
    const std::size_t bytes = one.outputs[i].total() * one.outputs[i].elemSize();
    ASSERT_EQ(bytes, again.outputs[i].total() * again.outputs[i].elemSize());
    ASSERT_EQ(bytes, other.outputs[i].total() * other.outputs[i].elemSize());
    EXPECT_EQ(std::memcmp(one.outputs[i].data, again.outputs[i].data, bytes), 0) << "output " << i;
    EXPECT_EQ(std::memcmp(one.outputs[i].data, other.outputs[i].data, bytes), 0) << "output " << i;
  }
  const Anchors anchors = first.run(bgr);
  EXPECT_EQ(anchors.size(), expectRows);
  EXPECT_EQ(anchors.classes(), 80);
  // The most confident person row sits on one of the frame's two people (label_2/000000.txt: a
  // cyclist at x 737.6-931.1, y 161.5-374.0 and a pedestrian at x 1106.1-1204.5, y 166.6-323.9).
  double best = 0;
  cv::Point at;
  cv::minMaxLoc(anchors.scores.col(0), nullptr, &best, nullptr, &at);
  EXPECT_GT(best, 0.5);
  const Box& b = anchors.boxes[static_cast<std::size_t>(at.y)];
  const bool onCyclist = b.centerX() > 737.6 && b.centerX() < 931.1 && b.centerY() > 161.5 && b.centerY() < 374.0;
  const bool onPedestrian = b.centerX() > 1106.1 && b.centerX() < 1204.5 && b.centerY() > 166.6 && b.centerY() < 323.9;
  EXPECT_TRUE(onCyclist || onPedestrian) << b.x << " " << b.y << " " << b.w << " " << b.h;
}

TEST(Network, Yolov5SameBytesEveryRun) { expectSameBytes(yolov5Spec(), 13104); }  // 3 x (104x32 + 52x16 + 26x8)
TEST(Network, DarknetSameBytesEveryRun) { expectSameBytes(darknetSpec(), 3120); }  // 3 x (26x8 + 52x16)

}  // namespace
}  // namespace fusedet::fusion
