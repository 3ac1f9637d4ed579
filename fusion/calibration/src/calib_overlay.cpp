// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/calibration/calib_overlay.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::fusion {

cv::Mat drawLaserOverlay(const cv::Mat& image, const Sweep& sweep, const Eigen::Matrix3d& K,
                         const Eigen::Isometry3d& laserToCamera, double maxRange) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument("overlay: image must be 8-bit grey or BGR");
  cv::Mat grey, out;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  // Dimmed so that the coloured dots stand out.
  cv::cvtColor(grey * 0.6, out, cv::COLOR_GRAY2BGR);
  cv::Mat lut(1, 256, CV_8UC1);
  for (int i = 0; i < 256; ++i) lut.at<std::uint8_t>(i) = static_cast<std::uint8_t>(i);
  cv::Mat colours;
  cv::applyColorMap(lut, colours, cv::COLORMAP_JET);
  for (const SweepPoint& p : sweep.points) {
    const Eigen::Vector3d c = laserToCamera * Eigen::Vector3d(p.x, p.y, p.z);
    if (!(c.z() > 0.5)) continue;
    const double range = c.norm();
    if (range > maxRange) continue;
    const Eigen::Vector3d px = K * c / c.z();
    const int u = static_cast<int>(std::lround(px.x())), v = static_cast<int>(std::lround(px.y()));
    if (u < 0 || v < 0 || u >= out.cols || v >= out.rows) continue;
    // Near = red (end of JET), far = blue.
    const int idx = 255 - std::clamp(static_cast<int>(255.0 * range / maxRange), 0, 255);
    cv::circle(out, {u, v}, 1, cv::Scalar(colours.at<cv::Vec3b>(0, idx)), cv::FILLED);
  }
  return out;
}

cv::Mat stackOverlays(const cv::Mat& top, const std::string& topCaption, const cv::Mat& bottom,
                      const std::string& bottomCaption) {
  if (top.type() != CV_8UC3 || bottom.type() != CV_8UC3 || top.cols != bottom.cols)
    throw std::invalid_argument("overlay: images to stack must be BGR of the same width");
  cv::Mat out;
  cv::vconcat(top, bottom, out);
  auto caption = [&](const std::string& text, int y) {
    cv::putText(out, text, {10, y}, cv::FONT_HERSHEY_SIMPLEX, 0.8, cv::Scalar(0, 0, 0), 4, cv::LINE_AA);
    cv::putText(out, text, {10, y}, cv::FONT_HERSHEY_SIMPLEX, 0.8, cv::Scalar(255, 255, 255), 2, cv::LINE_AA);
  };
  caption(topCaption, 28);
  caption(bottomCaption, top.rows + 28);
  return out;
}

}  // namespace fusedet::fusion
