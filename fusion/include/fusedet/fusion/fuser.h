// SPDX-License-Identifier: Apache-2.0
#pragma once
// Fuser: one camera image + one sweep -> a LayerStack with the camera layers (red, green, blue,
// intensity, hue) at image resolution and the laser layers (distance, remission, with a validity
// mask) at their own lower resolution, registered through the undistorted image plane.
// The same code serves live data (distorted camera, extrinsics from config) and KITTI (rectified
// camera, calib files). With a network configured (NeuralLayers, fusion/neural) the stack also
// gets the network's score layers, made from the undistorted image (one code path for KITTI
// import, `fusedet detect` and fusedetd).

#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/neural/neural_layers.h"
#include "fusedet/fusion/projection.h"
#include "fusedet/fusion/sweep.h"
#include "fusedet/fusion/undistorter.h"

namespace fusedet::fusion {

// Wall time of each step of one fuse() call, in milliseconds.
struct FuseTimings {
  double undistortMs = 0, cameraLayersMs = 0, neuralMs = 0, projectMs = 0, rasteriseMs = 0, totalMs = 0;
};

class Fuser {
 public:
  // sweepToCamera maps sweep points (Sweep::frame) to the camera frame (x right, y down, z ahead).
  // `neural` (optional): the network whose score layers every stack also gets.
  Fuser(const CameraModel& camera, const Eigen::Isometry3d& sweepToCamera, ProjectionConfig config = {},
        std::shared_ptr<const NeuralLayers> neural = {});

  // bgr: the camera image as captured (distorted, the model's size), CV_8UC3. The stack's stamp
  // and source are left to the caller.
  LayerStack fuse(const cv::Mat& bgr, const Sweep& sweep, FuseTimings* timings = nullptr) const;

  // fuse() in two steps, for a caller that runs the network on another thread (fusedetd's
  // pipeline): fuseSensors() makes every layer but the network's and hands out the undistorted
  // image; addNetworkLayers() then adds the network's layers from that image (nothing without a
  // network). fuse() is exactly these two calls.
  LayerStack fuseSensors(const cv::Mat& bgr, const Sweep& sweep, cv::Mat* undistorted,
                         FuseTimings* timings = nullptr) const;
  void addNetworkLayers(LayerStack& stack, const cv::Mat& undistorted, FuseTimings* timings = nullptr) const;

  // The layers fuse() makes, in its order (a model needing any other cannot run on its stacks;
  // hue_distance is derived from hue per model at detection time).
  static std::vector<std::string> layerNames();
  // The layers this Fuser's stacks have: layerNames(), then the network's when one is configured.
  std::vector<std::string> stackLayers() const;
  // The network that makes the stacks' neural layers (empty: none).
  NetworkRecord network() const { return neural_ ? neural_->record() : NetworkRecord{}; }
  const std::shared_ptr<const NeuralLayers>& neural() const { return neural_; }

  const PinholeProjection& projection() const { return projection_; }
  const ProjectionConfig& config() const { return config_; }
  const Undistorter& undistorter() const { return undistorter_; }

 private:
  PinholeProjection projection_;
  ProjectionConfig config_;
  Undistorter undistorter_;
  std::shared_ptr<const NeuralLayers> neural_;
};

}  // namespace fusedet::fusion
