// SPDX-License-Identifier: Apache-2.0
#pragma once
// The agreement measures of targetless calibration (see calib_targetless.h) at one pyramid level:
// the points are chosen and prepared once, then any transform is scored quickly.

#include <Eigen/Geometry>
#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <vector>

#include "fusedet/fusion/calibration/calib_targetless.h"

namespace fusedet::fusion::detail {

// Laser-side data, the same at every level.
struct LaserSamples {
  std::vector<Eigen::Vector3f> xyz;           // laser frame
  std::vector<std::uint8_t> remissionBin;     // remission, rank-quantised over all frames
  std::vector<Eigen::Vector3f> edgeXyz;       // the depth-edge points
  std::vector<float> edgeWeight;              // sqrt of the range jump [m^0.5]
  double edgeWeightSum = 0;
  std::vector<Eigen::Vector3f> plainXyz;      // every kPlainStride-th point that is no depth edge
};

// Image-side data of one frame at one level.
struct LevelImage {
  cv::Mat intensity;  // CV_32F, equalised grey scaled to [0, kIntensityBins)
  cv::Mat edges;      // CV_32F, edge strength spread by the max-decay filter, [0, 1]
};

inline constexpr int kIntensityBins = 32;
inline constexpr int kRemissionBins = 32;
inline constexpr int kPlainStride = 4;

// Picks each frame's points that land in front of the camera (with a margin around the image)
// under `reference`, marks depth edges along scan lines and rank-quantises remission.
std::vector<LaserSamples> prepareLaserSamples(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K,
                                              const Eigen::Isometry3d& reference, const TargetlessOptions& options);

// The image pyramid of one frame: level l has 1/2^l resolution; edges spread by edgeDecay per
// pixel of the level.
std::vector<LevelImage> prepareLevelImages(const cv::Mat& image, int levels, double edgeDecay);

class AlignmentCost {
 public:
  AlignmentCost(const std::vector<LaserSamples>& laser, const std::vector<std::vector<LevelImage>>& images,
                const Eigen::Matrix3d& K, int level);
  // Frames with skip[f] set are left out (jackknife); empty = all frames. Only the measures asked
  // for are computed (the other stays 0): the edge measure alone is about ten times cheaper.
  AlignmentScore score(const Eigen::Isometry3d& laserToCamera, const std::vector<bool>& skip = {},
                       AlignmentMeasure measure = AlignmentMeasure::kBoth) const;

 private:
  const std::vector<LaserSamples>& laser_;
  const std::vector<std::vector<LevelImage>>& images_;
  Eigen::Matrix3f K_;
  int level_;
};

}  // namespace fusedet::fusion::detail
