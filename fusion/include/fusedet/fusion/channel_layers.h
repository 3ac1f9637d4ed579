#pragma once
// Channels beyond the paper's seven layers, offered to the joint feature pool (issue 15):
//  - from intensity, aggregate channel features (Dollar et al., "Fast Feature Pyramids", 2014):
//    gradient magnitude `grad_mag` and six oriented-gradient channels `grad_0` .. `grad_5` (the
//    magnitude of pixels whose gradient orientation falls in bin k of six 30-degree bins over
//    [0, 180)), computed on the intensity image reduced by `ChannelConfig::gradientScale` (ACF's
//    aggregation; Haar-like features average them further);
//  - from the laser: `height` (metres above the ground plane fitted to the sweep's cells,
//    RANSAC with the plane's normal within 30 deg of the camera's up axis) and `distance_grad`
//    (depth gradient magnitude in metres per laser cell), on the laser grid with its mask.

#include <array>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>

#include "fusedet/core/layer_stack.h"

namespace fusedet::fusion {

namespace channel {
inline constexpr std::string_view kGradientMagnitude = "grad_mag";
inline constexpr std::array<std::string_view, 6> kOrientedGradient = {"grad_0", "grad_1", "grad_2",
                                                                        "grad_3", "grad_4", "grad_5"};
inline constexpr std::string_view kHeight = "height";
inline constexpr std::string_view kDistanceGradient = "distance_grad";
}  // namespace channel

struct ChannelConfig {
  double gradientScale = 0.5;  // gradient channels' size relative to the intensity layer, (0, 1]
  double groundInlier = 0.15;  // [m] cells this close to a candidate plane support it
  int ransacIterations = 200;
};

// Adds grad_mag and grad_0..grad_5 (CV_8U: magnitude / sqrt(2) of central differences, 0..255)
// computed from the stack's intensity layer. Throws std::out_of_range without intensity.
void addGradientChannels(LayerStack& stack, const ChannelConfig& config = {});

// Ground plane n.p + d = 0 (n unit, pointing up, i.e. n.y < 0 in camera coordinates), or none.
struct GroundPlane {
  Eigen::Vector3d normal = Eigen::Vector3d(0, -1, 0);
  double offset = 0;
  int inliers = 0;
};

// 3D points (camera frame) of the distance layer's valid cells: the ray through the cell's
// centre in image pixels (K, image of the stack's reference size) scaled to the cell's distance.
std::vector<Eigen::Vector3d> distanceCellPoints(const LayerStack& stack, const Eigen::Matrix3d& K);

// RANSAC plane with the most inliers among planes whose normal is within 30 deg of up;
// least-squares refit on them. Deterministic (fixed seed). None with fewer than 3 points.
std::optional<GroundPlane> fitGroundPlane(const std::vector<Eigen::Vector3d>& points, const ChannelConfig& config = {});

// Adds height and distance_grad from the stack's distance layer (same grid and mask). Without a
// ground plane (too few laser cells) height is 0 with an all-invalid mask.
void addLaserChannels(LayerStack& stack, const Eigen::Matrix3d& K, const ChannelConfig& config = {});

}  // namespace fusedet::fusion
