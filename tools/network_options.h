// SPDX-License-Identifier: Apache-2.0
#pragma once
// The options that name the network whose score layers a stack gets (fusion/neural/neural_layers.h),
// defined once for `fusedet import-kitti`, `fusedet detect` and `fusedet experiments`:
// --network KIND (none = off, the default), --network-file FILE (repeatable; default: the kind's
// files in the networks folder), --network-input WxH, --networks-dir DIR.

#include <CLI/CLI.hpp>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fusedet/fusion/neural/neural_layers.h"

namespace fusedet::tools {

struct NetworkOptions {
  std::string kind = "none";  // none | darknet | yolov5-onnx
  std::vector<std::filesystem::path> files;
  std::string input = "832x256";
  std::filesystem::path directory;  // empty: fusion::defaultNetworksDir()

  bool enabled() const { return kind != "none"; }
  fusion::NeuralLayerOptions layerOptions() const;
  // The loaded network, or null when --network is none. Throws naming the file and the problem.
  std::shared_ptr<const fusion::NeuralLayers> load() const;
  // The options as they would be given again, e.g. " --network darknet --network-input 832x256".
  std::string commandLine() const;
};

// `what` ends the --network help: what the layers are for in this command.
void addNetworkOptions(CLI::App& app, NetworkOptions& o, const std::string& what);

}  // namespace fusedet::tools
