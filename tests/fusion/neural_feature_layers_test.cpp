// SPDX-License-Identifier: Apache-2.0
// Backbone feature layers (fusion/neural/feature_layers.h): the channel choice and the sampling on
// worked examples written by hand, then a real KITTI frame through both networks against a plain
// evaluation in this file - its own input image, cv::dnn asked for the tap layer directly, the
// head's weights read and ranked by its own loops, its own bilinear sampling.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/dnn.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fusedet/fusion/neural/feature_layers.h"
#include "fusedet/fusion/neural/neural_layers.h"

namespace fusedet::fusion {
namespace {
namespace fs = std::filesystem;

const fs::path kModels = FUSEDET_NETWORKS_DIR;
const fs::path kFrame = fs::path(FUSEDET_DATA_DIR) / "kitti/image_2/000000.png";

TEST(FeatureChannels, WorkedExampleByHand) {
  // 2 anchors x (5 + 1 class) outputs x 4 channels; objectness rows are outputs 4 and 10.
  cv::Mat w(12, 4, CV_32F, cv::Scalar(9));  // every other output weighs 9: must not count
  const cv::Mat objectness0 = (cv::Mat_<float>(1, 4) << 0.1f, -0.5f, 0.2f, 0.0f);
  const cv::Mat objectness1 = (cv::Mat_<float>(1, 4) << 0.3f, 0.1f, -0.2f, 0.4f);
  objectness0.copyTo(w.row(4));
  objectness1.copyTo(w.row(10));
  // |.| summed: 0.4, 0.6, 0.4, 0.4 -> channel 1, then 0, 2, 3 (ties: the lower index first).
  EXPECT_EQ(chooseFeatureChannels(w, 6, 4), (std::vector<int>{1, 0, 2, 3}));
  EXPECT_EQ(chooseFeatureChannels(w, 6, 2), (std::vector<int>{1, 0}));
  const int shape[] = {12, 4, 1, 1};  // the 1x1 convolution's blob
  EXPECT_EQ(chooseFeatureChannels(cv::Mat(4, shape, CV_32F, w.data), 6, 1), (std::vector<int>{1}));
  EXPECT_THROW(chooseFeatureChannels(w, 5, 1), std::invalid_argument);  // 12 outputs are not anchors of 5
  EXPECT_THROW(chooseFeatureChannels(w, 6, 5), std::invalid_argument);
  EXPECT_THROW(chooseFeatureChannels(w, 6, 0), std::invalid_argument);
  EXPECT_EQ(featureLayerName(3), "neural_feature_3");
}

TEST(FeatureMap, WorkedExampleByHand) {
  // A 16 x 4 image letterboxed into a 16 x 8 input (scale 1, 2 rows of padding above), tapped at
  // stride 4: a 4 x 2 feature map, cell centres at input x 2, 6, 10, 14 and y 2, 6.
  const int shape[] = {1, 2, 2, 4};
  cv::Mat tap(4, shape, CV_32F);
  float* v = tap.ptr<float>();
  for (int i = 0; i < 16; ++i) v[i] = float(i);  // channel 0: rows 0..3, 4..7; channel 1: 8..15
  InputGeometry g;
  g.image = {16, 4};
  g.input = {16, 8};
  g.padY = 2;
  // A 4 x 1 grid: centres at image (2, 2), (6, 2), ... -> input y 4 -> feature y 0.5, x 0, 1, 2, 3.
  const cv::Mat m = featureMap(tap, 1, g, 4, 1);
  const cv::Mat expected = (cv::Mat_<float>(1, 4) << 10, 11, 12, 13);  // (8 + 12) / 2, ...
  EXPECT_EQ(cv::norm(m, expected, cv::NORM_INF), 0.0) << m;
  // An 8 x 2 grid: x centres 1, 3, ... -> feature x -0.25 (clamped to 0), 0.25, ..., 3.25 (to 3);
  // y centres 1, 3 -> input 3, 5 -> feature 0.25, 0.75.
  const cv::Mat fine = featureMap(tap, 0, g, 8, 2);
  EXPECT_FLOAT_EQ(fine.at<float>(0, 0), 0 + 0.25f * 4);
  EXPECT_FLOAT_EQ(fine.at<float>(0, 1), 0.25f + 0.25f * 4);
  EXPECT_FLOAT_EQ(fine.at<float>(1, 7), 3 + 0.75f * 4);
  EXPECT_THROW(featureMap(tap, 2, g, 4, 1), std::invalid_argument);
  EXPECT_THROW(featureMap(tap, 0, g, 0, 1), std::invalid_argument);

  LayerStack stack(32, 8);  // a reference twice the image: the grid covers the same view
  addFeatureLayers(stack, tap, {1, 0}, g, 0.25);
  ASSERT_TRUE(stack.has("neural_feature_0") && stack.has("neural_feature_1"));
  EXPECT_EQ(cv::norm(stack.at("neural_feature_0").data, featureMap(tap, 1, g, 8, 2), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(stack.at("neural_feature_1").data, fine, cv::NORM_INF), 0.0);
}

// The plain evaluation: the tap of `tapName` for the network's input image `input`, and the
// `count` channels of `headName` with the largest summed |objectness weight|.
struct Plain {
  cv::Mat tap;
  std::vector<int> channels;
};

Plain plainTap(cv::dnn::Net net, const cv::Mat& input, const std::string& tapName,
               const std::string& headName, int count) {
  net.setInput(cv::dnn::blobFromImage(input, 1 / 255.0, cv::Size(), cv::Scalar(), true, false));
  Plain p;
  p.tap = net.forward(tapName).clone();
  const cv::Mat w = net.getParam(headName, 0);
  const int outputs = w.size[0], channels = w.size[1];
  std::vector<double> sum(channels, 0.0);
  for (int o = 4; o < outputs; o += 85)
    for (int c = 0; c < channels; ++c) sum[c] += std::abs(w.ptr<float>(o)[c]);
  for (int k = 0; k < count; ++k) {
    int best = -1;
    for (int c = 0; c < channels; ++c)
      if (std::find(p.channels.begin(), p.channels.end(), c) == p.channels.end() &&
          (best < 0 || sum[c] > sum[best]))
        best = c;
    p.channels.push_back(best);
  }
  return p;
}

// The value at image point (px, py) by the plain tap: the point through the given mapping to
// feature cells (scale and pad already divided by the stride), sampled bilinearly.
double plainCell(const cv::Mat& tap, int channel, double px, double py, double sx, double sy, double padX,
                 double padY) {
  const int h = tap.size[2], w = tap.size[3];
  const auto at = [&](int y, int x) { return double(tap.ptr<float>(0, channel)[y * w + x]); };
  const double u = std::clamp((px * sx + padX) - 0.5, 0.0, double(w - 1));
  const double v = std::clamp((py * sy + padY) - 0.5, 0.0, double(h - 1));
  const int x0 = int(u), y0 = int(v), x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, h - 1);
  const double fx = u - x0, fy = v - y0;
  return (1 - fy) * ((1 - fx) * at(y0, x0) + fx * at(y0, x1)) +
         fy * ((1 - fx) * at(y1, x0) + fx * at(y1, x1));
}

void expectFeatureLayersMatchPlain(const NeuralLayerOptions& options, bool yolov5) {
  const cv::Mat bgr = cv::imread(kFrame.string());
  ASSERT_FALSE(bgr.empty()) << kFrame;
  const NeuralLayers layers(options);
  LayerStack stack(bgr.cols, bgr.rows);
  layers.add(stack, bgr);
  const std::vector<std::string> names = layers.layerNames();
  ASSERT_EQ(names.size(), 3u + options.features);
  EXPECT_EQ(names.back(), "neural_feature_" + std::to_string(options.features - 1));

  // The input image: YOLOv5 letterbox (1242 x 375 -> 832 x 251, 2 grey rows above), Darknet resize.
  cv::Mat input;
  double sx = 832.0 / bgr.cols, sy = 256.0 / bgr.rows, padX = 0, padY = 0;
  cv::dnn::Net net;
  std::string tapName, headName;
  if (yolov5) {
    const double r = std::min(sx, sy);
    const int w = int(std::lround(bgr.cols * r)), h = int(std::lround(bgr.rows * r));
    padX = (832 - w) / 2;
    padY = (256 - h) / 2;
    cv::Mat small;
    cv::resize(bgr, small, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
    cv::copyMakeBorder(small, input, int(padY), 256 - h - int(padY), int(padX), 832 - w - int(padX),
                       cv::BORDER_CONSTANT, cv::Scalar(114, 114, 114));
    sx = sy = r;
    net = cv::dnn::readNet((kModels / "yolov5n_256x832.onnx").string());
    tapName = "onnx_node!/model.17/cv3/act/Mul";
    headName = "onnx_node!/model.24/m.0/Conv";
  } else {
    cv::resize(bgr, input, cv::Size(832, 256), 0, 0, cv::INTER_LINEAR);
    net = cv::dnn::readNetFromDarknet((kModels / "yolo-fastest-1.1-xl.cfg").string(),
                                      (kModels / "yolo-fastest-1.1-xl.weights").string());
    tapName = "bn_128";
    headName = "conv_129";
  }
  const Plain plain = plainTap(net, input, tapName, headName, options.features);
  const double stride = 832.0 / plain.tap.size[3];
  EXPECT_EQ(stride, yolov5 ? 8.0 : 16.0);
  for (int k = 0; k < options.features; ++k) {
    const Layer& l = stack.at(names[3 + k]);
    ASSERT_EQ(l.width(), 621);
    ASSERT_EQ(l.height(), 188);
    double maxDiff = 0, spread = 0, lo = 1e9, hi = -1e9;
    for (int y = 0; y < l.height(); y += 3)
      for (int x = 0; x < l.width(); x += 3) {
        const double px = (x + 0.5) * bgr.cols / 621.0, py = (y + 0.5) * bgr.rows / 188.0;
        const double want = plainCell(plain.tap, plain.channels[k], px, py, sx / stride, sy / stride,
                                      padX / stride, padY / stride);
        maxDiff = std::max(maxDiff, std::abs(want - l.data.at<float>(y, x)));
        lo = std::min(lo, want);
        hi = std::max(hi, want);
      }
    spread = hi - lo;
    EXPECT_LT(maxDiff, 1e-4 * std::max(1.0, spread))
        << names[3 + k] << " (channel " << plain.channels[k] << ")";
    EXPECT_GT(spread, 0.1) << names[3 + k] << ": a real frame's channel varies";
  }
}

TEST(FeatureLayers, Yolov5OnAKittiFrameMatchesAPlainEvaluation) {
  NeuralLayerOptions o;
  o.kind = NetworkKind::yolov5Onnx;
  o.directory = kModels;
  o.features = 8;
  expectFeatureLayersMatchPlain(o, true);
}

TEST(FeatureLayers, DarknetOnAKittiFrameMatchesAPlainEvaluation) {
  NeuralLayerOptions o;
  o.directory = kModels;
  o.features = 8;
  expectFeatureLayersMatchPlain(o, false);
}

// A run that keeps no tap adds nothing and says so; too many channels are refused at load.
TEST(FeatureLayers, ARunWithoutItsTapAddsNothingAndTooManyChannelsAreRefused) {
  NeuralLayerOptions o;
  o.directory = kModels;
  o.features = 2;
  const NeuralLayers layers(o, [](Network& n, const cv::Mat& bgr) {
    Anchors a = n.run(bgr);
    n.takeFeatures();
    return a;
  });
  const cv::Mat bgr = cv::imread(kFrame.string());
  LayerStack stack(bgr.cols, bgr.rows);
  try {
    layers.add(stack, bgr);
    ADD_FAILURE() << "added " << stack.size() << " layers";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(": output of no feature map"), std::string::npos) << e.what();
  }
  EXPECT_EQ(stack.size(), 0u);
  o.features = 145;  // Yolo-Fastest-XL's tap has 144
  try {
    NeuralLayers tooMany(o);
    ADD_FAILURE() << "loaded";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("145 of 144 channels"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace fusedet::fusion
