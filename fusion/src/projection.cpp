// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/projection.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::fusion {

std::vector<ProjectedPoint> projectPoints(const Sweep& sweep, const PinholeProjection& pr, double minDepth) {
  if (pr.width <= 0 || pr.height <= 0) throw std::invalid_argument("projectPoints: image size not set");
  const Eigen::Matrix3d R = pr.sweepToCamera.linear();
  const Eigen::Vector3d t = pr.sweepToCamera.translation();
  const Eigen::Matrix3d& K = pr.K;
  const double w = pr.width, h = pr.height;
  std::vector<ProjectedPoint> out;
  out.reserve(sweep.points.size() / 3);
  for (std::size_t i = 0; i < sweep.points.size(); ++i) {
    const SweepPoint& p = sweep.points[i];
    const Eigen::Vector3d c = R * Eigen::Vector3d(p.x, p.y, p.z) + t;
    if (!(c.z() >= minDepth)) continue;  // behind the camera, too close, or NaN
    const double iz = 1.0 / c.z();
    const double u = (K(0, 0) * c.x() + K(0, 1) * c.y()) * iz + K(0, 2);
    const double v = K(1, 1) * c.y() * iz + K(1, 2);
    if (!(u >= 0 && u < w && v >= 0 && v < h)) continue;
    out.push_back(ProjectedPoint{static_cast<std::uint32_t>(i), static_cast<float>(u), static_cast<float>(v),
                                 static_cast<float>(c.norm()), std::clamp(p.remission, 0.f, 1.f)});
  }
  return out;
}

cv::Size laserLayerSize(int width, int height, double scale) {
  if (!(scale > 0 && scale <= 1)) throw std::invalid_argument("laser layer scale must be in (0, 1]");
  return {std::max(1, static_cast<int>(std::lround(width * scale))),
          std::max(1, static_cast<int>(std::lround(height * scale)))};
}

LaserLayers rasteriseLaserLayers(const std::vector<ProjectedPoint>& points, int imageWidth, int imageHeight,
                                 const ProjectionConfig& config) {
  const cv::Size size = laserLayerSize(imageWidth, imageHeight, config.laserLayerScale);
  cv::Mat dist(size, CV_32FC1, cv::Scalar(0)), rem(size, CV_32FC1, cv::Scalar(0));
  cv::Mat mask(size, CV_8UC1, cv::Scalar(0));
  const float sx = static_cast<float>(size.width) / static_cast<float>(imageWidth);
  const float sy = static_cast<float>(size.height) / static_cast<float>(imageHeight);
  for (const ProjectedPoint& p : points) {
    const int cx = std::min(static_cast<int>(p.u * sx), size.width - 1);
    const int cy = std::min(static_cast<int>(p.v * sy), size.height - 1);
    if (cx < 0 || cy < 0) continue;
    std::uint8_t& m = mask.at<std::uint8_t>(cy, cx);
    float& d = dist.at<float>(cy, cx);
    if (m == 0 || p.distance < d) {  // z-buffer: the nearest point of a cell wins
      m = kMaskMeasured;
      d = p.distance;
      rem.at<float>(cy, cx) = p.remission;
    }
  }
  fillHoles({&dist, &rem}, mask, config.holeFillRadius);
  return LaserLayers{Layer{std::string(layer::kDistance), dist, mask},
                     Layer{std::string(layer::kRemission), rem, mask.clone()}};
}

void fillHoles(std::vector<cv::Mat*> values, cv::Mat& mask, int radius) {
  if (radius <= 0) return;
  // Normalised convolution with weights 1 / (dx^2 + dy^2), centre 0: each empty cell gets the
  // weighted mean of the measured cells around it. Scattered from the measured cells (a few
  // per cent of the grid with KITTI, more with a dense scanner) instead of gathered at every cell.
  struct Tap {
    int dx, dy;
    float w;
  };
  std::vector<Tap> taps;
  for (int dy = -radius; dy <= radius; ++dy)
    for (int dx = -radius; dx <= radius; ++dx)
      if (dx != 0 || dy != 0) taps.push_back({dx, dy, 1.f / static_cast<float>(dx * dx + dy * dy)});
  const int rows = mask.rows, cols = mask.cols;
  cv::Mat weight(rows, cols, CV_32FC1, cv::Scalar(0));
  std::vector<cv::Mat> sums;
  for (std::size_t i = 0; i < values.size(); ++i) sums.emplace_back(rows, cols, CV_32FC1, cv::Scalar(0));
  for (int y = 0; y < rows; ++y) {
    const std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    for (int x = 0; x < cols; ++x) {
      if (m[x] != kMaskMeasured) continue;
      const bool inner = x >= radius && y >= radius && x < cols - radius && y < rows - radius;
      for (const Tap& t : taps) {
        const int nx = x + t.dx, ny = y + t.dy;
        if (!inner && (nx < 0 || ny < 0 || nx >= cols || ny >= rows)) continue;
        weight.ptr<float>(ny)[nx] += t.w;
        for (std::size_t i = 0; i < values.size(); ++i)
          sums[i].ptr<float>(ny)[nx] += t.w * values[i]->ptr<float>(y)[x];
      }
    }
  }
  for (int y = 0; y < rows; ++y) {
    std::uint8_t* m = mask.ptr<std::uint8_t>(y);
    const float* w = weight.ptr<float>(y);
    for (int x = 0; x < cols; ++x) {
      if (m[x] != 0 || w[x] <= 0.f) continue;
      m[x] = kMaskFilled;
      for (std::size_t i = 0; i < values.size(); ++i)
        values[i]->ptr<float>(y)[x] = sums[i].ptr<float>(y)[x] / w[x];
    }
  }
}

}  // namespace fusedet::fusion
