// SPDX-License-Identifier: Apache-2.0
#pragma once
// The network as one more layer source of a stack (issue 30; paper §3.2: one more sensor in the
// joint feature pool). NeuralLayers runs the configured network once on a stack's camera image
// and adds its score layers (score_layers.h: neural_person, neural_bicycle, neural_car) and the
// network's record (LayerStack::network). The Fuser calls it (fuser.h), so KITTI import, training
// data, `fusedet detect` and fusedetd make these layers by the same code.
//
// Defaults: Yolo-Fastest-XL (Darknet, public domain: may be bundled) at 832 x 256, its files
// `yolo-fastest-1.1-xl.cfg` and `.weights` in the networks folder; YOLOv5n's default file is
// `yolov5n_256x832.onnx` (AGPL-3.0: user-supplied only). The networks folder: the option given,
// else $FUSEDET_NETWORKS_DIR, else /usr/share/fusedet/networks.

#include <filesystem>
#include <functional>
#include <mutex>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/neural/network.h"
#include "fusedet/fusion/neural/score_layers.h"

namespace fusedet::fusion {

struct NeuralLayerOptions {
  NetworkKind kind = NetworkKind::darknet;
  std::vector<std::filesystem::path> files;  // empty: the kind's default files in `directory`
  std::filesystem::path directory;           // empty: defaultNetworksDir()
  cv::Size input{832, 256};                  // W x H
  double scale = 0.5;                        // score layers' grid relative to the reference size
  int threads = 1;                           // OpenCV threads during a run
};

// $FUSEDET_NETWORKS_DIR, else /usr/share/fusedet/networks.
std::filesystem::path defaultNetworksDir();
// The files of `kind` in `directory`: darknet -> yolo-fastest-1.1-xl.cfg, .weights; yolov5-onnx ->
// yolov5n_256x832.onnx.
std::vector<std::filesystem::path> defaultNetworkFiles(NetworkKind kind, const std::filesystem::path& directory);
// The spec the options name (files resolved: given files relative to `directory` when relative).
NetworkSpec networkSpecFor(const NeuralLayerOptions& options);

// What runs the loaded network on one image: Network::run unless given (a test wraps it to make
// a run fail the ways a real one can: cv::dnn throwing, an output of another shape).
using NetworkRun = std::function<Anchors(Network&, const cv::Mat&)>;

class NeuralLayers {
 public:
  // Loads the network; throws std::runtime_error naming the file and the problem (network.h).
  explicit NeuralLayers(const NeuralLayerOptions& options, NetworkRun run = {});

  // Runs the network on `bgr` (8-bit BGR, the stack's camera image: its size is the stack's
  // reference size or proportional to it) and adds the score layers and the network's record to
  // `stack`. One run at a time (a mutex): safe to call from several threads.
  // A run that fails adds nothing and throws std::runtime_error naming the network and the
  // problem: cv::dnn threw, or the output is not what the network gave at load (the number of
  // anchor rows and classes; every score finite and in [0, 1], every box finite).
  void add(LayerStack& stack, const cv::Mat& bgr) const;

  const NetworkIdentity& identity() const { return network_.identity(); }
  NetworkRecord record() const { return network_.identity().record(); }
  // The layers add() makes, in its order.
  std::vector<std::string> layerNames() const;
  double scale() const { return scale_; }
  // OpenCV threads of a run (NeuralLayerOptions::threads).
  int threads() const { return network_.spec().threads; }

 private:
  mutable std::mutex mutex_;
  mutable Network network_;
  NetworkRun run_;
  double scale_;
};

}  // namespace fusedet::fusion
