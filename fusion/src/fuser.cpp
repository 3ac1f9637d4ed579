// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/fuser.h"

#include <chrono>
#include <stdexcept>

#include "fusedet/fusion/camera_layers.h"

namespace fusedet::fusion {
namespace {
using Clock = std::chrono::steady_clock;
double msSince(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}
}  // namespace

Fuser::Fuser(const CameraModel& camera, const Eigen::Isometry3d& sweepToCamera, ProjectionConfig config,
             std::shared_ptr<const NeuralLayers> neural)
    : config_(config), undistorter_(camera), neural_(std::move(neural)) {
  projection_.K = camera.K;
  projection_.sweepToCamera = sweepToCamera;
  projection_.width = camera.width;
  projection_.height = camera.height;
  (void)laserLayerSize(camera.width, camera.height, config_.laserLayerScale);  // validates the scale
  if (config_.holeFillRadius < 0) throw std::invalid_argument("hole fill radius must be >= 0");
}

std::vector<std::string> Fuser::layerNames() {
  return {std::string(layer::kRed),       std::string(layer::kGreen),    std::string(layer::kBlue),
          std::string(layer::kIntensity), std::string(layer::kHue),      std::string(layer::kDistance),
          std::string(layer::kRemission)};
}

std::vector<std::string> Fuser::stackLayers() const {
  std::vector<std::string> names = layerNames();
  if (neural_)
    for (std::string& n : neural_->layerNames()) names.push_back(std::move(n));
  return names;
}

LayerStack Fuser::fuse(const cv::Mat& bgr, const Sweep& sweep, FuseTimings* timings) const {
  const auto start = Clock::now();
  FuseTimings t;
  cv::Mat image;
  LayerStack stack = fuseSensors(bgr, sweep, &image, &t);
  addNetworkLayers(stack, image, &t);
  t.totalMs = msSince(start);
  if (timings) *timings = t;
  return stack;
}

LayerStack Fuser::fuseSensors(const cv::Mat& bgr, const Sweep& sweep, cv::Mat* undistorted, FuseTimings* timings) const {
  FuseTimings t;
  const auto start = Clock::now();
  auto t0 = start;
  cv::Mat image = undistorter_.undistort(bgr);
  t.undistortMs = msSince(t0);

  t0 = Clock::now();
  LayerStack stack;
  addCameraLayers(stack, image);
  t.cameraLayersMs = msSince(t0);

  t0 = Clock::now();
  const std::vector<ProjectedPoint> points = projectPoints(sweep, projection_, config_.minDepth);
  t.projectMs = msSince(t0);

  t0 = Clock::now();
  LaserLayers laser = rasteriseLaserLayers(points, projection_.width, projection_.height, config_);
  stack.set(std::move(laser.distance));
  stack.set(std::move(laser.remission));
  t.rasteriseMs = msSince(t0);
  t.totalMs = msSince(start);
  if (undistorted) *undistorted = std::move(image);
  if (timings) *timings = t;
  return stack;
}

void Fuser::addNetworkLayers(LayerStack& stack, const cv::Mat& undistorted, FuseTimings* timings) const {
  if (!neural_) return;
  const auto t0 = Clock::now();
  neural_->add(stack, undistorted);
  if (timings) timings->neuralMs = msSince(t0);
}

}  // namespace fusedet::fusion
