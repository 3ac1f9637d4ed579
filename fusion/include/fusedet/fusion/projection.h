// SPDX-License-Identifier: Apache-2.0
#pragma once
// Projection of a sweep into the (undistorted) camera image plane and rasterisation into the
// laser layers `distance` and `remission` at their own, lower resolution (paper §3.1, design §4):
// a z-buffer keeps the nearest point per cell, holes are interpolated up to a radius, and a mask
// says which cells hold data.

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/sweep.h"

namespace fusedet::fusion {

struct ProjectionConfig {
  double laserLayerScale = 0.5;  // laser layers' size relative to the camera image, (0, 1]
  int holeFillRadius = 2;        // fill empty cells with a measured cell this close (Chebyshev)
  double minDepth = 0.05;        // [m] points closer to the image plane (or behind it) are dropped
};

// The pinhole the points are projected with: pixel ~ K * (sweepToCamera * p), camera frame
// x right, y down, z forward. `distance` is |sweepToCamera * p|, the range from the camera centre.
struct PinholeProjection {
  Eigen::Matrix3d K = Eigen::Matrix3d::Identity();
  Eigen::Isometry3d sweepToCamera = Eigen::Isometry3d::Identity();
  int width = 0, height = 0;  // image the pixels refer to
};

// A point that lands in the image: u, v continuous pixel coordinates (pixel (i, j) covers
// [i, i+1) x [j, j+1)), distance [m], remission clamped to [0, 1].
struct ProjectedPoint {
  std::uint32_t index = 0;  // into Sweep::points
  float u = 0, v = 0;
  float distance = 0;
  float remission = 0;
};

// Points with camera depth < minDepth, or outside [0, width) x [0, height), are dropped.
std::vector<ProjectedPoint> projectPoints(const Sweep& sweep, const PinholeProjection& projection,
                                          double minDepth);

// Size of the laser layers for an image of width x height (rounded, at least 1).
cv::Size laserLayerSize(int width, int height, double scale);

// Mask values of the laser layers: measured by a point, or interpolated by hole filling.
inline constexpr std::uint8_t kMaskMeasured = 255;
inline constexpr std::uint8_t kMaskFilled = 128;

struct LaserLayers {
  Layer distance;   // CV_32F metres, 0 where invalid
  Layer remission;  // CV_32F [0, 1], 0 where invalid; same mask as distance
};

// Z-buffer rasterisation (nearest point per cell wins) of points projected into an image of
// imageWidth x imageHeight, then hole filling (fillHoles). Cell of a point: floor(u * cols / imageWidth).
LaserLayers rasteriseLaserLayers(const std::vector<ProjectedPoint>& points, int imageWidth,
                                 int imageHeight, const ProjectionConfig& config);

// Fills each empty cell (mask 0) that has a measured cell within `radius` (Chebyshev) with the
// inverse-square-distance weighted mean of the measured cells within that radius; marks it
// kMaskFilled. Larger holes stay 0 and invalid. values: CV_32F, mask: CV_8U, same size.
void fillHoles(std::vector<cv::Mat*> values, cv::Mat& mask, int radius);

}  // namespace fusedet::fusion
