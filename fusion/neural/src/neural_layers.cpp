// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/neural_layers.h"

#include <cstdlib>
#include <stdexcept>

namespace fusedet::fusion {

std::filesystem::path defaultNetworksDir() {
  if (const char* env = std::getenv("FUSEDET_NETWORKS_DIR"); env && *env) return env;
  return "/usr/share/fusedet/networks";
}

std::vector<std::filesystem::path> defaultNetworkFiles(NetworkKind kind, const std::filesystem::path& directory) {
  if (kind == NetworkKind::darknet)
    return {directory / "yolo-fastest-1.1-xl.cfg", directory / "yolo-fastest-1.1-xl.weights"};
  return {directory / "yolov5n_256x832.onnx"};
}

NetworkSpec networkSpecFor(const NeuralLayerOptions& o) {
  const std::filesystem::path dir = o.directory.empty() ? defaultNetworksDir() : o.directory;
  NetworkSpec spec;
  spec.kind = o.kind;
  spec.input = o.input;
  spec.threads = o.threads;
  if (o.files.empty()) {
    spec.files = defaultNetworkFiles(o.kind, dir);
  } else {
    for (const auto& f : o.files) spec.files.push_back(f.is_relative() ? dir / f : f);
  }
  return spec;
}

NeuralLayers::NeuralLayers(const NeuralLayerOptions& options) : network_(networkSpecFor(options)), scale_(options.scale) {
  if (!(scale_ > 0 && scale_ <= 1))
    throw std::runtime_error("neural layers: scale must be in (0, 1], got " + std::to_string(scale_));
}

void NeuralLayers::add(LayerStack& stack, const cv::Mat& bgr) const {
  if (stack.width() < 1 || stack.height() < 1)
    throw std::invalid_argument("neural layers: the stack has no reference size");
  Anchors anchors;
  {
    std::lock_guard lock(mutex_);
    anchors = network_.run(bgr);
  }
  // The image may be smaller than the reference grid (camera layers at a lower resolution): the
  // boxes go to reference pixels.
  const double sx = static_cast<double>(stack.width()) / bgr.cols, sy = static_cast<double>(stack.height()) / bgr.rows;
  if (sx != 1.0 || sy != 1.0)
    for (Box& b : anchors.boxes) b = Box{b.x * sx, b.y * sy, b.w * sx, b.h * sy};
  addScoreLayers(stack, anchors, scale_);
  stack.network = record();
}

std::vector<std::string> NeuralLayers::layerNames() const {
  std::vector<std::string> names;
  for (const ScoreLayerClass& c : defaultScoreLayers()) names.push_back(c.layer);
  return names;
}

}  // namespace fusedet::fusion
