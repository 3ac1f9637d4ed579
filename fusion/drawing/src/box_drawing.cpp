// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/drawing/box_drawing.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <opencv2/imgproc.hpp>

namespace fusedet::fusion {
namespace {

void dashedRect(cv::Mat& img, const cv::Rect& r, const cv::Scalar& colour) {
  const cv::Point c[4] = {r.tl(), {r.x + r.width, r.y}, r.br(), {r.x, r.y + r.height}};
  for (int side = 0; side < 4; ++side) {
    const cv::Point a = c[side], b = c[(side + 1) % 4];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    for (double t = 0; t < len; t += 12) {
      const double t1 = std::min(len, t + 6);
      cv::line(img, a + (b - a) * (t / len), a + (b - a) * (t1 / len), colour, 1, cv::LINE_AA);
    }
  }
}

}  // namespace

void drawBoxes(cv::Mat& tile, double scale, const Labels& labels, const std::vector<Detection>& detections) {
  const auto rect = [scale](const Box& b) {
    return cv::Rect(cvRound(b.x * scale), cvRound(b.y * scale), cvRound(b.w * scale), cvRound(b.h * scale));
  };
  const cv::Scalar teacherColour(255, 255, 0);  // cyan: a network drew it, a person should check it
  for (const Label& l : labels) {
    const bool teacher = l.origin == "teacher";
    if (l.ignore) {
      dashedRect(tile, rect(l.box), teacher ? teacherColour : cv::Scalar(170, 170, 170));
      continue;
    }
    const cv::Scalar colour = teacher ? teacherColour : l.className == "van" ? cv::Scalar(0, 165, 255) : cv::Scalar(0, 220, 0);
    const cv::Rect r = rect(l.box);
    cv::rectangle(tile, r, colour, teacher ? 1 : 2);
    cv::putText(tile, teacher ? l.className + " (teacher)" : l.className, r.tl() + cv::Point(2, 14),
                cv::FONT_HERSHEY_SIMPLEX, 0.45, colour, 1, cv::LINE_AA);
  }
  for (const Detection& d : detections) {
    const cv::Rect r = rect(d.box);
    cv::rectangle(tile, r, cv::Scalar(0, 0, 255), 2);
    char text[96];
    std::snprintf(text, sizeof text, "%s %.2f", d.className.c_str(), d.score);
    cv::putText(tile, text, cv::Point(r.x + 2, r.y + r.height - 4), cv::FONT_HERSHEY_SIMPLEX, 0.45,
                cv::Scalar(0, 0, 255), 1, cv::LINE_AA);
  }
}

}  // namespace fusedet::fusion
