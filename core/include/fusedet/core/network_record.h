// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which pretrained network made a stack's neural layers (`neural_<class>`, fusion/neural): its
// kind, input size and the SHA-256 of each model file. A stack carries it (data set item.json
// "network"), a cascade trained on such layers records it (model file "network"), and detection
// refuses layers of another network: the same layer name from another network is another feature.
//
// Text form (item.json, model files, messages), file names without folders and without spaces:
//   "darknet 832x256 yolo-fastest-1.1-xl.cfg sha256:<64 hex> yolo-fastest-1.1-xl.weights sha256:<64 hex>"

#include <string>
#include <string_view>
#include <vector>

namespace fusedet {

struct NetworkRecord {
  std::string kind;  // "darknet" | "yolov5-onnx"; empty = no network
  int inputWidth = 0, inputHeight = 0;
  std::vector<std::string> fileNames;  // without folders
  std::vector<std::string> sha256;     // lower-case hex, parallel to fileNames

  bool empty() const { return kind.empty(); }
  std::string text() const;  // "" when empty
  bool operator==(const NetworkRecord&) const = default;
};

// The text form back; "" gives an empty record. Throws std::invalid_argument naming the text and
// what is wrong (no "WxH", a file without "sha256:", a digest that is not 64 hex digits).
NetworkRecord parseNetworkRecord(std::string_view text);

// Layers a network makes are named "neural_<class>".
bool isNetworkLayer(std::string_view layer);
bool usesNetworkLayers(const std::vector<std::string>& layers);

// Throws std::runtime_error when layers `made` (of `layersName`, e.g. a stack or a daemon's
// configured network) cannot serve a model that needs `wanted` (of `modelName`): one of them
// empty, or the two differ. The message names both networks (text form) and what to do.
void requireSameNetwork(const NetworkRecord& wanted, const std::string& modelName, const NetworkRecord& made,
                        const std::string& layersName);

}  // namespace fusedet
