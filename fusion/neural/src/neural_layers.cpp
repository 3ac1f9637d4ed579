// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/neural_layers.h"

#include <cmath>
#include <cstdlib>
#include <opencv2/core.hpp>
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

namespace {

// Why a run's output is not what the network gave at load (empty: it is).
std::string outputProblem(const Anchors& a, std::size_t rows, int classes) {
  if (a.size() != rows || a.objectness.size() != rows || static_cast<std::size_t>(a.scores.rows) != rows ||
      a.scores.cols != classes)
    return std::to_string(a.size()) + " anchor rows x " + std::to_string(a.scores.cols) + " classes where it gave " +
           std::to_string(rows) + " x " + std::to_string(classes) + " at load";
  if (a.scores.type() != CV_32F) return "class scores that are not float";
  if (!cv::checkRange(a.scores, true)) return "a class score that is not finite";
  double lo = 0, hi = 0;
  if (!a.scores.empty()) cv::minMaxLoc(a.scores, &lo, &hi);
  if (lo < 0 || hi > 1) return "a class score outside [0, 1] (" + std::to_string(lo < 0 ? lo : hi) + ")";
  for (const Box& b : a.boxes)
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.w) || !std::isfinite(b.h))
      return "a box that is not finite";
  return {};
}

}  // namespace

NeuralLayers::NeuralLayers(const NeuralLayerOptions& options, NetworkRun run)
    : network_(networkSpecFor(options)), run_(std::move(run)), scale_(options.scale) {
  if (!(scale_ > 0 && scale_ <= 1))
    throw std::runtime_error("neural layers: scale must be in (0, 1], got " + std::to_string(scale_));
  if (!run_) run_ = [](Network& n, const cv::Mat& bgr) { return n.run(bgr); };
}

void NeuralLayers::add(LayerStack& stack, const cv::Mat& bgr) const {
  if (stack.width() < 1 || stack.height() < 1)
    throw std::invalid_argument("neural layers: the stack has no reference size");
  Anchors anchors;
  const auto failed = [&](const std::string& problem) {
    return std::runtime_error("network " + network_.identity().text() + " on a " + std::to_string(bgr.cols) + "x" +
                              std::to_string(bgr.rows) + " image: " + problem);
  };
  {
    std::lock_guard lock(mutex_);
    try {
      anchors = run_(network_, bgr);
    } catch (const cv::Exception& e) {
      throw failed("cv::dnn failed: " + e.err);
    } catch (const std::exception& e) {
      throw failed(e.what());
    }
  }
  if (const std::string problem = outputProblem(anchors, network_.anchorRows(), network_.classes()); !problem.empty())
    throw failed("output of " + problem);
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
