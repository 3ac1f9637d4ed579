// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/layer_sources.h"

#include "fusedet/core/layer_stack.h"
#include "fusedet/core/network_record.h"
#include "fusedet/fusion/neural/score_layers.h"

namespace fusedet::fusion {

LayerSource layerSource(std::string_view l) {
  for (std::string_view c : {layer::kRed, layer::kGreen, layer::kBlue, layer::kIntensity, layer::kHue,
                             layer::kHueDistance})
    if (l == c) return LayerSource::camera;
  if (l == layer::kDistance || l == layer::kRemission) return LayerSource::laser;
  if (isNetworkLayer(l)) return LayerSource::network;
  return LayerSource::unknown;
}

std::string toString(LayerSource s) {
  switch (s) {
    case LayerSource::camera: return "camera";
    case LayerSource::laser: return "laser";
    case LayerSource::network: return "network";
    case LayerSource::unknown: break;
  }
  return "other";
}

const std::vector<std::string>& paperPoolLayers() {
  static const std::vector<std::string> l = {std::string(layer::kRed),       std::string(layer::kGreen),
                                             std::string(layer::kBlue),      std::string(layer::kIntensity),
                                             std::string(layer::kHueDistance), std::string(layer::kDistance),
                                             std::string(layer::kRemission)};
  return l;
}

const std::vector<std::string>& networkPoolLayers() {
  static const std::vector<std::string> l = [] {
    std::vector<std::string> names;
    for (const ScoreLayerClass& c : defaultScoreLayers()) names.push_back(c.layer);
    return names;
  }();
  return l;
}

std::map<std::string, double> sharesBySource(const std::map<std::string, double>& shares) {
  std::map<std::string, double> bySource;
  for (const auto& [l, s] : shares) bySource[toString(layerSource(l))] += s;
  return bySource;
}

}  // namespace fusedet::fusion
