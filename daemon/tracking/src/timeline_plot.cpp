// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/timeline_plot.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <opencv2/imgproc.hpp>

namespace fusedet::tracking {
namespace {

constexpr int kCell = 14, kRow = 18, kLeft = 90, kRight = 20, kTitle = 26, kGap = 14;
const cv::Scalar kWhite(255, 255, 255), kBlack(0, 0, 0), kGrey(170, 170, 170), kRed(40, 40, 220), kOrange(0, 140, 255);

// A distinct, stable colour per track id (golden-angle hue steps).
cv::Scalar colourOf(std::int64_t id) {
  const double hue = std::fmod(static_cast<double>(id) * 137.508, 360.0);
  cv::Mat hsv(1, 1, CV_8UC3, cv::Scalar(hue / 2, 170, 220)), bgr;
  cv::cvtColor(hsv, bgr, cv::COLOR_HSV2BGR);
  const cv::Vec3b c = bgr.at<cv::Vec3b>(0, 0);
  return {static_cast<double>(c[0]), static_cast<double>(c[1]), static_cast<double>(c[2])};
}

void text(cv::Mat& img, const std::string& s, cv::Point at, double scale, const cv::Scalar& colour) {
  cv::putText(img, s, at, cv::FONT_HERSHEY_SIMPLEX, scale, colour, 1, cv::LINE_AA);
}

// Truth ids in order of first appearance.
std::vector<std::int64_t> rowsOf(const ClearMotTimeline& t) {
  std::vector<std::int64_t> rows;
  for (const auto& frame : t)
    for (const TruthEvent& e : frame)
      if (std::find(rows.begin(), rows.end(), e.truth) == rows.end()) rows.push_back(e.truth);
  return rows;
}

}  // namespace

cv::Mat drawTimeline(const std::vector<TimelinePanel>& panels, const std::string& caption) {
  std::size_t frames = 1;
  int height = kTitle + 40;  // caption + legend
  for (const TimelinePanel& p : panels) {
    frames = std::max(frames, p.timeline.size());
    height += kTitle + static_cast<int>(std::max<std::size_t>(1, rowsOf(p.timeline).size())) * kRow + 20 + kGap;
  }
  const int width = std::max(760, kLeft + static_cast<int>(frames) * kCell + kRight);
  cv::Mat img(height, width, CV_8UC3, kWhite);
  text(img, caption, {8, 18}, 0.5, kBlack);
  int y = kTitle;
  for (const TimelinePanel& p : panels) {
    text(img, p.title, {8, y + 16}, 0.45, kBlack);
    y += kTitle;
    const std::vector<std::int64_t> rows = rowsOf(p.timeline);
    std::map<std::int64_t, int> rowOf;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      rowOf[rows[r]] = static_cast<int>(r);
      text(img, "object " + std::to_string(rows[r]), {8, y + static_cast<int>(r) * kRow + 13}, 0.38, kBlack);
    }
    std::map<std::int64_t, std::int64_t> lastHyp;
    for (std::size_t k = 0; k < p.timeline.size(); ++k)
      for (const TruthEvent& e : p.timeline[k]) {
        const int x = kLeft + static_cast<int>(k) * kCell, top = y + rowOf[e.truth] * kRow;
        const cv::Rect cell(x + 1, top + 2, kCell - 2, kRow - 4);
        if (!e.hypothesis) {
          cv::rectangle(img, cell, kGrey, 1);
          continue;
        }
        cv::rectangle(img, cell, colourOf(*e.hypothesis), cv::FILLED);
        const auto last = lastHyp.find(e.truth);
        if (last == lastHyp.end() || last->second != *e.hypothesis || e.resumed)
          text(img, std::to_string(*e.hypothesis), {x + 1, top - 1 + kRow / 2 + 4}, 0.3, kBlack);
        lastHyp[e.truth] = *e.hypothesis;
        if (e.idSwitch) cv::rectangle(img, cv::Rect(x - 1, top, 3, kRow), kRed, cv::FILLED);
        if (e.resumed) {
          const std::vector<cv::Point> tri{{x, top + kRow - 1}, {x + 6, top + kRow - 1}, {x, top + kRow - 7}};
          cv::fillConvexPoly(img, tri, kOrange);
        }
      }
    y += static_cast<int>(std::max<std::size_t>(1, rows.size())) * kRow;
    // Frame axis: a tick every 10 frames.
    for (std::size_t k = 0; k < frames; k += 10) {
      const int x = kLeft + static_cast<int>(k) * kCell;
      cv::line(img, {x, y + 2}, {x, y + 6}, kBlack);
      text(img, std::to_string(k), {x + 2, y + 16}, 0.33, kBlack);
    }
    y += 20 + kGap;
  }
  text(img, "columns: stacks (one per KITTI frame); cell colour + number: the track matched (IoU >= 0.5);", {8, y + 4}, 0.36, kBlack);
  text(img, "grey outline: missed; red bar: id switch; orange corner: fragmentation", {8, y + 20}, 0.36, kBlack);
  return img;
}

}  // namespace fusedet::tracking
