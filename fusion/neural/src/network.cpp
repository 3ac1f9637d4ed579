// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/network.h"

#include <fstream>
#include <opencv2/core/utils/logger.hpp>
#include <opencv2/dnn.hpp>
#include <stdexcept>

#include "fusedet/fusion/neural/sha256.h"

namespace fusedet::fusion {
namespace {

std::string sizeText(cv::Size s) { return std::to_string(s.width) + "x" + std::to_string(s.height); }

std::string joinedNames(const std::vector<std::filesystem::path>& files) {
  std::string s;
  for (const auto& f : files) s += (s.empty() ? "" : ", ") + f.string();
  return s;
}

// A Darknet cfg is text whose first section is [net] (or [network]); an ONNX file is a protobuf
// that cv::dnn's ONNX importer parses. Checked before cv::dnn sees the files, so a wrong kind is
// named as such rather than as an assertion inside OpenCV.
bool looksLikeDarknetCfg(const std::filesystem::path& file) {
  std::ifstream in(file);
  std::string line;
  while (std::getline(in, line)) {
    const auto start = line.find_first_not_of(" \t\r");
    if (start == std::string::npos || line[start] == '#' || line[start] == ';') continue;
    return line.compare(start, 5, "[net]") == 0 || line.compare(start, 9, "[network]") == 0;
  }
  return false;
}

// Silences cv::dnn's own error log while a failure is expected to be reported by us.
class QuietOpenCv {
 public:
  QuietOpenCv() : previous_(cv::utils::logging::setLogLevel(cv::utils::logging::LOG_LEVEL_SILENT)) {}
  ~QuietOpenCv() { cv::utils::logging::setLogLevel(previous_); }
  QuietOpenCv(const QuietOpenCv&) = delete;
  QuietOpenCv& operator=(const QuietOpenCv&) = delete;

 private:
  cv::utils::logging::LogLevel previous_;
};

// Rows a YOLOv5 output has at this input: 3 anchors per cell of the stride 8, 16, 32 grids.
int yolov5Rows(cv::Size input) {
  int n = 0;
  for (int s : {8, 16, 32}) n += 3 * ((input.width + s - 1) / s) * ((input.height + s - 1) / s);
  return n;
}

}  // namespace

NetworkKind parseNetworkKind(std::string_view text) {
  if (text == "darknet") return NetworkKind::darknet;
  if (text == "yolov5-onnx") return NetworkKind::yolov5Onnx;
  throw std::invalid_argument("unknown network kind '" + std::string(text) + "' (darknet, yolov5-onnx)");
}

cv::Size parseInputSize(std::string_view text) {
  const std::size_t x = text.find('x');
  int w = 0, h = 0;
  const auto number = [](std::string_view t, int& v) {
    if (t.empty() || t.size() > 5) return false;
    for (char c : t)
      if (c < '0' || c > '9') return false;
    v = std::stoi(std::string(t));
    return v > 0;
  };
  if (x == std::string_view::npos || !number(text.substr(0, x), w) || !number(text.substr(x + 1), h))
    throw std::invalid_argument("network input size '" + std::string(text) + "': expected WxH in pixels, e.g. 832x256");
  return {w, h};
}

std::string toString(NetworkKind kind) { return kind == NetworkKind::darknet ? "darknet" : "yolov5-onnx"; }

NetworkRecord NetworkIdentity::record() const {
  return NetworkRecord{toString(kind), input.width, input.height, fileNames, sha256};
}

struct Network::Impl {
  cv::dnn::Net net;
  std::vector<std::string> outputNames;
};

Network::Network(const NetworkSpec& spec) : spec_(spec), impl_(std::make_unique<Impl>()) {
  const std::string kind = toString(spec.kind);
  const std::size_t expectFiles = spec.kind == NetworkKind::darknet ? 2 : 1;
  if (spec.files.size() != expectFiles)
    throw std::runtime_error("network (" + kind + "): expected " +
                             (expectFiles == 2 ? std::string("a cfg and a weights file") : std::string("one .onnx file")) +
                             ", got " + std::to_string(spec.files.size()) + " file(s): " + joinedNames(spec.files));
  for (const auto& f : spec.files)
    if (!std::filesystem::is_regular_file(f))
      throw std::runtime_error(f.string() + ": network file (" + kind + ") not found");
  if (spec.input.width <= 0 || spec.input.height <= 0)
    throw std::runtime_error(spec.files.front().string() + ": input size " + sizeText(spec.input) + " is not positive");
  if (spec.kind == NetworkKind::darknet && (spec.input.width % 32 || spec.input.height % 32))
    throw std::runtime_error(spec.files.front().string() + ": Darknet input size " + sizeText(spec.input) +
                             " is not a multiple of 32 in both directions");
  if (spec.threads < 1) throw std::runtime_error("network: threads must be >= 1, got " + std::to_string(spec.threads));

  identity_.kind = spec.kind;
  identity_.input = spec.input;
  for (const auto& f : spec.files) {
    if (f.filename().string().find(' ') != std::string::npos)
      throw std::runtime_error(f.string() + ": a network file name must not contain spaces (stacks and models record it)");
    identity_.fileNames.push_back(f.filename().string());
    identity_.sha256.push_back(sha256File(f));
  }

  if (spec.kind == NetworkKind::darknet && !looksLikeDarknetCfg(spec.files[0]))
    throw std::runtime_error(spec.files[0].string() + ": not a Darknet cfg (no [net] section first); kind " + kind +
                             " wants the cfg, then the weights");
  if (spec.kind == NetworkKind::yolov5Onnx && looksLikeDarknetCfg(spec.files[0]))
    throw std::runtime_error(spec.files[0].string() + ": a Darknet cfg, not an ONNX file (kind " + kind + ")");
  {
    QuietOpenCv quiet;
    try {
      impl_->net = spec.kind == NetworkKind::darknet
                       ? cv::dnn::readNetFromDarknet(spec.files[0].string(), spec.files[1].string())
                       : cv::dnn::readNetFromONNX(spec.files[0].string());
    } catch (const cv::Exception& e) {
      throw std::runtime_error(joinedNames(spec.files) + ": cv::dnn cannot load it as " + kind + ": " + e.err);
    }
  }
  if (impl_->net.empty()) throw std::runtime_error(joinedNames(spec.files) + ": cv::dnn loaded an empty " + kind + " network");
  impl_->net.setPreferableBackend(cv::dnn::DNN_BACKEND_OPENCV);
  impl_->net.setPreferableTarget(cv::dnn::DNN_TARGET_CPU);
  impl_->outputNames = impl_->net.getUnconnectedOutLayersNames();

  // One run on a grey image: the input size is accepted and the output has the kind's shape.
  NetworkOutput probe;
  try {
    QuietOpenCv quiet;
    probe = forward(cv::Mat(spec.input, CV_8UC3, cv::Scalar(114, 114, 114)));
  } catch (const cv::Exception& e) {
    throw std::runtime_error(spec.files.front().string() + ": the network refuses input size " + sizeText(spec.input) +
                             " (W x H): " + e.err);
  }
  try {
    const Anchors a = spec.kind == NetworkKind::darknet ? decodeDarknet(probe.outputs, probe.geometry)
                                                        : decodeYolov5(probe.outputs.at(0), probe.geometry);
    if (spec.kind == NetworkKind::yolov5Onnx && static_cast<int>(a.size()) != yolov5Rows(spec.input))
      throw std::invalid_argument(std::to_string(a.size()) + " output rows where a YOLOv5 at " + sizeText(spec.input) +
                                  " has " + std::to_string(yolov5Rows(spec.input)));
    anchorRows_ = a.size();
    classes_ = a.scores.cols;
  } catch (const std::exception& e) {
    throw std::runtime_error(spec.files.front().string() + ": not a " + kind + " detector at input size " +
                             sizeText(spec.input) + ": " + e.what());
  }
}

Network::~Network() = default;
Network::Network(Network&&) noexcept = default;
Network& Network::operator=(Network&&) noexcept = default;

NetworkOutput Network::forward(const cv::Mat& bgr) {
  if (bgr.empty() || bgr.type() != CV_8UC3)
    throw std::invalid_argument("network: expected a non-empty 8-bit BGR image");
  NetworkOutput out;
  out.geometry = spec_.kind == NetworkKind::darknet ? resizeGeometry(bgr.size(), spec_.input)
                                                    : letterboxGeometry(bgr.size(), spec_.input);
  const cv::Mat input = makeInputImage(bgr, out.geometry);
  // RGB, scaled 1/255, N x C x H x W; the image already has the input size.
  const cv::Mat blob = cv::dnn::blobFromImage(input, 1.0 / 255.0, cv::Size(), cv::Scalar(), true, false, CV_32F);
  const int previousThreads = cv::getNumThreads();
  const bool setThreads = previousThreads != spec_.threads;
  if (setThreads) cv::setNumThreads(spec_.threads);
  std::vector<cv::Mat> outputs;
  try {
    impl_->net.setInput(blob);
    impl_->net.forward(outputs, impl_->outputNames);
  } catch (...) {
    if (setThreads) cv::setNumThreads(previousThreads);
    throw;
  }
  if (setThreads) cv::setNumThreads(previousThreads);
  for (const cv::Mat& o : outputs) out.outputs.push_back(o.clone());
  return out;
}

Anchors Network::run(const cv::Mat& bgr) {
  const NetworkOutput o = forward(bgr);
  return spec_.kind == NetworkKind::darknet ? decodeDarknet(o.outputs, o.geometry) : decodeYolov5(o.outputs.at(0), o.geometry);
}

}  // namespace fusedet::fusion
