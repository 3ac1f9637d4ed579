// SPDX-License-Identifier: Apache-2.0
#pragma once
// One pretrained COCO detector run through OpenCV's cv::dnn: loaded with its kind and input size
// given explicitly, run once per image, its output decoded into anchor rows (anchors.h). Its
// identity (kind, input size, sha256 of each model file) goes with whatever it produced, so a
// consumer can tell which network made a layer.
//
// Kinds (../shared/models/SOURCE.md): `darknet` (cfg + weights, e.g. Yolo-Fastest-XL; the input
// W x H must be multiples of 32; plain resize) and `yolov5-onnx` (one .onnx file exported with a
// fixed input; letterbox). Loading runs the network once on a grey image of the input size, so an
// input size the network refuses fails at load, naming the file.
//
// Determinism: cv::dnn's CPU backend, float32, and OpenCV's thread count set to `threads` (a
// process-wide OpenCV setting) for each run where it differs, and set back after it; the same
// image gives the same output bytes. A process that runs OpenCV on other threads at the same time
// sets the count to `threads` once before they start (fusedetd's pipeline does): a run then never
// changes it (with TBB, OpenCV's setNumThreads rebuilds the arena other threads may be working in).

#include <cstdint>
#include <filesystem>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "fusedet/core/network_record.h"
#include "fusedet/fusion/neural/anchors.h"
#include "fusedet/fusion/neural/input_geometry.h"

namespace fusedet::fusion {

enum class NetworkKind { darknet, yolov5Onnx };
// "darknet" | "yolov5-onnx"; throws std::invalid_argument naming the accepted kinds.
NetworkKind parseNetworkKind(std::string_view text);
std::string toString(NetworkKind kind);
// "832x256" (W x H, pixels) -> the size; throws std::invalid_argument naming the text otherwise.
cv::Size parseInputSize(std::string_view text);

struct NetworkSpec {
  NetworkKind kind = NetworkKind::yolov5Onnx;
  std::vector<std::filesystem::path> files;  // darknet: cfg, weights; yolov5-onnx: the .onnx file
  cv::Size input;                            // W x H the network runs at
  int threads = 1;                           // OpenCV threads during a run
};

struct NetworkIdentity {
  NetworkKind kind = NetworkKind::yolov5Onnx;
  std::vector<std::string> fileNames;  // file names without folders, as given
  std::vector<std::string> sha256;     // lower-case hex, parallel to fileNames
  cv::Size input;
  // The same as core's NetworkRecord, which stacks and model files carry.
  NetworkRecord record() const;
  // "yolov5-onnx 832x256 yolov5n_256x832.onnx sha256:a4e8..." (every file with its digest).
  std::string text() const { return record().text(); }
  bool operator==(const NetworkIdentity& o) const {
    return kind == o.kind && fileNames == o.fileNames && sha256 == o.sha256 && input == o.input;
  }
};

// The raw output of one run and how the image entered the input.
struct NetworkOutput {
  InputGeometry geometry;
  std::vector<cv::Mat> outputs;  // cv::dnn's unconnected output layers, in its order (owned copies)
};

class Network {
 public:
  // Throws std::runtime_error naming the file and the problem: a missing or unreadable file, a
  // file that is not of `kind`, a wrong number of files, an input size that is not positive, not
  // a multiple of 32 (darknet) or refused by the network.
  explicit Network(const NetworkSpec& spec);
  ~Network();
  Network(Network&&) noexcept;
  Network& operator=(Network&&) noexcept;

  const NetworkIdentity& identity() const { return identity_; }
  const NetworkSpec& spec() const { return spec_; }
  // Anchor rows and class columns of run()'s output, as the probe at load found them: every run
  // of this network has this shape (the input size is fixed).
  std::size_t anchorRows() const { return anchorRows_; }
  int classes() const { return classes_; }

  // One forward pass on an 8-bit BGR image of any size.
  NetworkOutput forward(const cv::Mat& bgr);
  // forward() decoded by the kind's convention (anchors.h): boxes in the image's pixels.
  Anchors run(const cv::Mat& bgr);

 private:
  struct Impl;
  NetworkSpec spec_;
  NetworkIdentity identity_;
  std::size_t anchorRows_ = 0;
  int classes_ = 0;
  std::unique_ptr<Impl> impl_;
};

}  // namespace fusedet::fusion
