// SPDX-License-Identifier: Apache-2.0
#pragma once
// Scenes a synthetic laser scans (synth-log): rays in the laser base frame (x ahead, y left,
// z up) -> the first surface hit. CloudScene resamples a measured cloud (a KITTI Velodyne sweep);
// ProceduralScene is known geometry without external data (ground plane, boxes, a back wall),
// which can also render the camera's view of itself.

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>
#include <optional>
#include <vector>

#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/synthesis/point_ray_caster.h"

namespace fusedet::fusion {

class SynthScene {
 public:
  virtual ~SynthScene() = default;
  virtual std::optional<RayHit> cast(const Eigen::Vector3d& origin, const Eigen::Vector3d& direction) const = 0;
};

class CloudScene : public SynthScene {
 public:
  CloudScene(const Sweep& cloud, double toleranceRad) : caster_(cloud, toleranceRad) {}
  std::optional<RayHit> cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const override { return caster_.cast(o, d); }

 private:
  PointRayCaster caster_;
};

class ProceduralScene : public SynthScene {
 public:
  struct Box {
    Eigen::Vector3d min, max;  // axis-aligned [m]
    float remission;
    cv::Vec3b colour;          // BGR
  };
  // Ground plane z = groundZ, boxes shifted by `shift` along x (so consecutive frames differ).
  explicit ProceduralScene(double shift = 0.0);
  std::optional<RayHit> cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const override;
  // The camera image of the scene: camera (x right, y down, z ahead) at baseToCamera^-1.
  cv::Mat render(const CameraModel& camera, const Eigen::Isometry3d& baseToCamera) const;

  static constexpr double kGroundZ = -1.73;  // a KITTI-like mounting height
  const std::vector<Box>& boxes() const { return boxes_; }

 private:
  // Index of what was hit: -1 ground, >= 0 box, nothing: no hit within maxRange.
  std::optional<std::pair<double, int>> hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const;
  std::vector<Box> boxes_;
};

}  // namespace fusedet::fusion
