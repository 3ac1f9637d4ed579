// SPDX-License-Identifier: Apache-2.0
// Neural score layers (fusion/neural/score_layers.h): a worked example whose cell values are
// written by hand, and a real KITTI frame through both networks against a plain evaluation in this
// file - its own letterbox / resize, cv::dnn called directly, its own reading of the rows and a
// brute-force maximum over every row for each cell (no code shared with the library's decoder).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <opencv2/dnn.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <random>

#include "fusedet/fusion/neural/network.h"
#include "fusedet/fusion/neural/score_layers.h"

namespace fusedet::fusion {
namespace {
namespace fs = std::filesystem;

const fs::path kModels = FUSEDET_NETWORKS_DIR;
const fs::path kFrame = fs::path(FUSEDET_DATA_DIR) / "kitti/image_2/000000.png";

TEST(ScoreLayers, WorkedExampleByHand) {
  // A 40 x 20 image on a 4 x 2 grid: cells 10 x 10 px, centres x 5, 15, 25, 35 and y 5, 15.
  Anchors a;
  a.boxes = {Box{0, 0, 20, 20},     // covers centres x 5, 15; y 5, 15
             Box{12, 8, 20, 4},     // y 8-12 holds centre 15? no (12 < 15); centre 5? no: covers nothing
             Box{14, 0, 2, 10},     // x 14-16 holds 15, y 0-10 holds 5: cell (1, 0)
             Box{30, 10, 10, 10}};  // x 30-40 holds 35, y 10-20 holds 15: cell (3, 1)
  a.objectness = {1, 1, 1, 1};
  a.scores = (cv::Mat_<float>(4, 2) << 0.2f, 0.9f,  //
              0.99f, 0.5f,                          //
              0.7f, 0.1f,                           //
              0.4f, 0.0f);
  const cv::Mat m = scoreMap(a, 0, 40, 20, 4, 2);
  const cv::Mat expected = (cv::Mat_<float>(2, 4) << 0.2f, 0.7f, 0.0f, 0.0f,  //
                            0.2f, 0.2f, 0.0f, 0.4f);
  EXPECT_EQ(cv::norm(m, expected, cv::NORM_INF), 0.0) << m;
  const cv::Mat c1 = scoreMap(a, 1, 40, 20, 4, 2);
  const cv::Mat expected1 = (cv::Mat_<float>(2, 4) << 0.9f, 0.9f, 0.0f, 0.0f,  //
                             0.9f, 0.9f, 0.0f, 0.0f);
  EXPECT_EQ(cv::norm(c1, expected1, cv::NORM_INF), 0.0) << c1;
  EXPECT_THROW(scoreMap(a, 2, 40, 20, 4, 2), std::invalid_argument);
  EXPECT_THROW(scoreMap(a, 0, 40, 20, 0, 2), std::invalid_argument);

  LayerStack stack(40, 20);
  addScoreLayers(stack, a, 0.1, {{"neural_a", 0}, {"neural_b", 1}});
  ASSERT_TRUE(stack.has("neural_a"));
  EXPECT_EQ(stack.at("neural_a").width(), 4);
  EXPECT_EQ(stack.at("neural_a").height(), 2);
  EXPECT_EQ(cv::norm(stack.at("neural_b").data, expected1, cv::NORM_INF), 0.0);
  EXPECT_EQ(defaultScoreLayers().size(), 3u);
  EXPECT_EQ(defaultScoreLayers()[0].layer, "neural_person");
}

// The plain evaluation: rows of the network's output in image pixels with the score of `classId`.
struct PlainRow {
  double x0, y0, x1, y1, score;
};

std::vector<PlainRow> plainYolov5(const cv::Mat& bgr, int classId) {
  // Letterbox: r = 832 / 1242 (the width binds), 1242 x 375 -> 832 x 251, 2 grey rows above.
  const double r = std::min(832.0 / bgr.cols, 256.0 / bgr.rows);
  const int w = int(std::lround(bgr.cols * r)), h = int(std::lround(bgr.rows * r));
  const int top = (256 - h) / 2, left = (832 - w) / 2;
  cv::Mat small, padded;
  cv::resize(bgr, small, cv::Size(w, h), 0, 0, cv::INTER_LINEAR);
  cv::copyMakeBorder(small, padded, top, 256 - h - top, left, 832 - w - left, cv::BORDER_CONSTANT,
                     cv::Scalar(114, 114, 114));
  cv::dnn::Net net = cv::dnn::readNet((kModels / "yolov5n_256x832.onnx").string());
  net.setInput(cv::dnn::blobFromImage(padded, 1 / 255.0, cv::Size(), cv::Scalar(), true, false));
  const cv::Mat out = net.forward();
  std::vector<PlainRow> rows;
  const float* p = reinterpret_cast<const float*>(out.data);
  for (int i = 0; i < out.size[1]; ++i, p += out.size[2])
    rows.push_back({(p[0] - p[2] / 2 - left) / r, (p[1] - p[3] / 2 - top) / r, (p[0] + p[2] / 2 - left) / r,
                    (p[1] + p[3] / 2 - top) / r, double(p[4] * p[5 + classId])});
  return rows;
}

std::vector<PlainRow> plainDarknet(const cv::Mat& bgr, int classId) {
  cv::Mat resized;
  cv::resize(bgr, resized, cv::Size(832, 256), 0, 0, cv::INTER_LINEAR);
  cv::dnn::Net net = cv::dnn::readNetFromDarknet((kModels / "yolo-fastest-1.1-xl.cfg").string(),
                                                 (kModels / "yolo-fastest-1.1-xl.weights").string());
  net.setInput(cv::dnn::blobFromImage(resized, 1 / 255.0, cv::Size(), cv::Scalar(), true, false));
  std::vector<cv::Mat> outs;
  net.forward(outs, net.getUnconnectedOutLayersNames());
  std::vector<PlainRow> rows;
  for (const cv::Mat& o : outs)
    for (int i = 0; i < o.rows; ++i) {
      const float* p = o.ptr<float>(i);
      rows.push_back({(p[0] - p[2] / 2) * bgr.cols, (p[1] - p[3] / 2) * bgr.rows, (p[0] + p[2] / 2) * bgr.cols,
                      (p[1] + p[3] / 2) * bgr.rows, double(p[5 + classId])});
    }
  return rows;
}

// The value a cell must have: the best score over the rows whose box holds the cell's centre.
double plainCell(const std::vector<PlainRow>& rows, double cx, double cy) {
  double best = 0;
  for (const PlainRow& r : rows)
    if (r.x0 <= cx && cx < r.x1 && r.y0 <= cy && cy < r.y1) best = std::max(best, r.score);
  return best;
}

void expectLayersMatchPlain(const NetworkSpec& spec, bool yolov5) {
  const cv::Mat bgr = cv::imread(kFrame.string());
  ASSERT_FALSE(bgr.empty()) << kFrame;
  Network net(spec);
  LayerStack stack(bgr.cols, bgr.rows);
  addScoreLayers(stack, net.run(bgr), 0.5);
  std::mt19937 rng(7);
  for (const ScoreLayerClass& c : defaultScoreLayers()) {
    const std::vector<PlainRow> rows = yolov5 ? plainYolov5(bgr, c.classId) : plainDarknet(bgr, c.classId);
    const Layer& l = stack.at(c.layer);
    ASSERT_EQ(l.width(), 621);  // 1242 x 375 at half resolution
    ASSERT_EQ(l.height(), 188);
    const double cellW = 1242.0 / 621, cellH = 375.0 / 188;
    // Every cell of every fourth row and column, plus the cell of the layer's maximum.
    double maxDiff = 0, layerMax = 0;
    cv::Point at;
    cv::minMaxLoc(l.data, nullptr, &layerMax, nullptr, &at);
    EXPECT_NEAR(layerMax, plainCell(rows, (at.x + 0.5) * cellW, (at.y + 0.5) * cellH), 1e-6) << c.layer;
    double plainMax = 0;
    for (int y = 0; y < l.height(); y += 4)
      for (int x = 0; x < l.width(); x += 4) {
        const double want = plainCell(rows, (x + 0.5) * cellW, (y + 0.5) * cellH);
        plainMax = std::max(plainMax, want);
        maxDiff = std::max(maxDiff, std::abs(want - l.data.at<float>(y, x)));
      }
    EXPECT_LT(maxDiff, 1e-6) << c.layer;
    if (c.layer != "neural_bicycle") {
      EXPECT_GT(plainMax, 0.5) << c.layer;  // frame 000000: a cyclist, a pedestrian, a van
    }
  }
}

TEST(ScoreLayers, Yolov5OnAKittiFrameMatchesAPlainEvaluation) {
  expectLayersMatchPlain({NetworkKind::yolov5Onnx, {kModels / "yolov5n_256x832.onnx"}, {832, 256}, 1}, true);
}

TEST(ScoreLayers, DarknetOnAKittiFrameMatchesAPlainEvaluation) {
  expectLayersMatchPlain(
      {NetworkKind::darknet, {kModels / "yolo-fastest-1.1-xl.cfg", kModels / "yolo-fastest-1.1-xl.weights"}, {832, 256}, 1},
      false);
}

}  // namespace
}  // namespace fusedet::fusion
