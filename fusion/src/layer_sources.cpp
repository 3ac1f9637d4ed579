#include "fusedet/fusion/layer_sources.h"

#include <algorithm>

#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/channel_layers.h"

namespace fusedet::fusion {

LayerSource layerSource(std::string_view l) {
  for (std::string_view c : {layer::kRed, layer::kGreen, layer::kBlue, layer::kIntensity, layer::kHue,
                             layer::kHueDistance})
    if (l == c) return LayerSource::camera;
  if (l == layer::kDistance || l == layer::kRemission) return LayerSource::laser;
  if (l == channel::kGradientMagnitude ||
      std::find(channel::kOrientedGradient.begin(), channel::kOrientedGradient.end(), l) !=
          channel::kOrientedGradient.end())
    return LayerSource::cameraDerived;
  if (l == channel::kHeight || l == channel::kDistanceGradient) return LayerSource::laserDerived;
  return LayerSource::unknown;
}

std::string toString(LayerSource s) {
  switch (s) {
    case LayerSource::camera: return "camera";
    case LayerSource::laser: return "laser";
    case LayerSource::cameraDerived: return "camera (derived)";
    case LayerSource::laserDerived: return "laser (derived)";
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

const std::vector<std::string>& extraChannelLayers() {
  static const std::vector<std::string> l = [] {
    std::vector<std::string> v{std::string(channel::kGradientMagnitude)};
    for (std::string_view g : channel::kOrientedGradient) v.emplace_back(g);
    v.emplace_back(channel::kHeight);
    v.emplace_back(channel::kDistanceGradient);
    return v;
  }();
  return l;
}

std::map<std::string, double> sharesBySource(const std::map<std::string, double>& shares) {
  std::map<std::string, double> bySource;
  for (const auto& [l, s] : shares) bySource[toString(layerSource(l))] += s;
  return bySource;
}

}  // namespace fusedet::fusion
