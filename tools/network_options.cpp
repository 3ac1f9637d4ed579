// SPDX-License-Identifier: Apache-2.0
#include "network_options.h"

namespace fusedet::tools {

fusion::NeuralLayerOptions NetworkOptions::layerOptions() const {
  fusion::NeuralLayerOptions o;
  o.kind = fusion::parseNetworkKind(kind);
  o.files = files;
  o.directory = directory;
  o.input = fusion::parseInputSize(input);
  return o;
}

std::shared_ptr<const fusion::NeuralLayers> NetworkOptions::load() const {
  if (!enabled()) return nullptr;
  return std::make_shared<const fusion::NeuralLayers>(layerOptions());
}

std::string NetworkOptions::commandLine() const {
  if (!enabled()) return "";
  std::string c = " --network " + kind;
  for (const auto& f : files) c += " --network-file " + f.string();
  c += " --network-input " + input;
  if (!directory.empty()) c += " --networks-dir " + directory.string();
  return c;
}

void addNetworkOptions(CLI::App& app, NetworkOptions& o, const std::string& what) {
  app.add_option("--network", o.kind,
                 "a pretrained COCO detector whose score layers (neural_person, neural_bicycle, neural_car) "
                 "the stacks get, run on each stack's camera image: darknet (Yolo-Fastest-XL by default) or "
                 "yolov5-onnx (YOLOv5n 832x256 by default; AGPL-3.0, never bundled); none = no neural layers. " +
                     what)
      ->check(CLI::IsMember({"none", "darknet", "yolov5-onnx"}))
      ->capture_default_str();
  app.add_option("--network-file", o.files,
                 "the network's files (darknet: the cfg, then the weights; yolov5-onnx: the .onnx), relative "
                 "ones in --networks-dir; default: yolo-fastest-1.1-xl.cfg + .weights, or yolov5n_256x832.onnx");
  app.add_option("--network-input", o.input, "the network's input size W x H (darknet: multiples of 32)")
      ->capture_default_str();
  app.add_option("--networks-dir", o.directory,
                 "where the network files are: default $FUSEDET_NETWORKS_DIR, else /usr/share/fusedet/networks");
}

}  // namespace fusedet::tools
