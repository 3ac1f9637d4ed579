// SPDX-License-Identifier: Apache-2.0
#pragma once
// Model files of our cascades: versioned, human-readable JSON (one stump per line), holding the
// class, window size (aspect ratio), layer names, reference hue and the stages with their
// thresholds and stumps (feature type letter, unit-square rectangle, layer name, threshold, two
// leaf values). Writing is deterministic: the same cascade gives the same bytes.
//
//   {
//     "format": "fusedet-cascade",
//     "version": 1,
//     "class": "car",
//     "window": {"width":40,"height":24},
//     "layers": ["intensity","distance"],
//     "reference_hue": 25,
//     "network": "darknet 832x256 yolo-fastest-1.1-xl.cfg sha256:... ...",  (only with neural_* layers:
//                the network that made them, fusedet/core/network_record.h)
//     "training": {"seed":"1", ...},          (optional, informative, ignored when loading)
//     "stages": [
//       {"threshold":-0.41,"stumps":[
//         {"type":"g","rect":[0.25,0,0.5,0.5],"layer":"distance","threshold":0.12,"left":-0.8,"right":0.5},
//         ...
//       ]},
//       ...
//     ]
//   }

#include <filesystem>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "fusedet/boost/cascade.h"

namespace fusedet::boosting {

// The one version this build reads and writes. Versions 2-5 were written only for options that
// measured no gain across drives and were removed with them (issue 29): loading such a file fails
// with a ModelError naming the version, the option and what to do (retrain with `fusedet train`):
// 2 contrast normalisation, 3 soft cascade, 4 side-view (aspect) cascades, 5 tree weak learners.
inline constexpr int kModelFormatVersion = 1;
inline constexpr const char* kModelFormatName = "fusedet-cascade";

// Any problem reading or writing a model: "<file>: <place>: <reason>", e.g.
// "car.json: stages[2].stumps[5].threshold: expected a number, got string".
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// Informative key/value pairs written under "training" (kept in the given order).
using ModelInfo = std::vector<std::pair<std::string, std::string>>;

std::string modelToText(const Cascade& cascade, const ModelInfo& info = {});
// `source` names the text in messages (usually the file name).
Cascade modelFromText(const std::string& text, const std::string& source);

// Throws ModelError (unwritable file, OpenCV-imported cascade, invalid cascade).
void saveModel(const Cascade& cascade, const std::filesystem::path& file, const ModelInfo& info = {});
// Throws ModelError naming the file, the place and the reason. Cascade::source = file.
Cascade loadModel(const std::filesystem::path& file);
// The informative "training" pairs of a model file (empty when it has none; values that are not
// strings as JSON text). Throws ModelError for an unreadable file or text that is not JSON.
ModelInfo loadModelInfo(const std::filesystem::path& file);

}  // namespace fusedet::boosting
