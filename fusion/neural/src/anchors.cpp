// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/anchors.h"

#include <opencv2/core.hpp>

#include <stdexcept>
#include <string>

namespace fusedet::fusion {
namespace {

std::string shapeText(const cv::Mat& m) {
  std::string s;
  for (int i = 0; i < m.dims; ++i) s += (i ? " x " : "") + std::to_string(m.size[i]);
  return s.empty() ? "empty" : s;
}

// The output as a 2-D rows x (5 + classes) float matrix (a view, no copy).
cv::Mat asRows(const cv::Mat& m, const char* what) {
  cv::Mat rows;
  if (m.type() == CV_32F && m.dims == 3 && m.size[0] == 1) rows = cv::Mat(m.size[1], m.size[2], CV_32F, m.data);
  else if (m.type() == CV_32F && m.dims == 2) rows = m;
  if (rows.empty() || rows.cols < 6 || !rows.isContinuous())
    throw std::invalid_argument(std::string(what) + " output of shape " + shapeText(m) +
                                " is not rows x (5 + classes) float");
  return rows;
}

// Appends the rows of one output; `unit` scales cx, cy, w, h to input pixels (1 for YOLOv5, the
// input size for Darknet); `objectnessTimesClass` multiplies the class columns by the objectness.
void append(Anchors& a, const cv::Mat& rows, const InputGeometry& g, double unitX, double unitY,
            bool objectnessTimesClass) {
  const int classes = rows.cols - 5;
  if (!a.scores.empty() && a.scores.cols != classes)
    throw std::invalid_argument("network outputs disagree on the number of classes (" +
                                std::to_string(a.scores.cols) + " and " + std::to_string(classes) + ")");
  cv::Mat scores(rows.rows, classes, CV_32F);
  for (int r = 0; r < rows.rows; ++r) {
    const float* p = rows.ptr<float>(r);
    const double w = p[2] * unitX, h = p[3] * unitY;
    a.boxes.push_back(g.toImage(Box{p[0] * unitX - w / 2, p[1] * unitY - h / 2, w, h}));
    a.objectness.push_back(p[4]);
    float* s = scores.ptr<float>(r);
    for (int c = 0; c < classes; ++c) s[c] = objectnessTimesClass ? p[4] * p[5 + c] : p[5 + c];
  }
  if (a.scores.empty()) a.scores = scores;
  else cv::vconcat(a.scores, scores, a.scores);
}

}  // namespace

Anchors decodeYolov5(const cv::Mat& output, const InputGeometry& g) {
  Anchors a;
  append(a, asRows(output, "YOLOv5"), g, 1.0, 1.0, true);
  return a;
}

Anchors decodeDarknet(const std::vector<cv::Mat>& outputs, const InputGeometry& g) {
  if (outputs.empty()) throw std::invalid_argument("Darknet network gave no output");
  Anchors a;
  for (const cv::Mat& o : outputs) append(a, asRows(o, "Darknet"), g, g.input.width, g.input.height, false);
  return a;
}

}  // namespace fusedet::fusion
