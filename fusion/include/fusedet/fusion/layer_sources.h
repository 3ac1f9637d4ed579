#pragma once
// Which sensor a layer of the joint feature pool comes from, so a cascade's weight share per layer
// can be summed per source: what each sensor and each derived channel contributes (issue 15).
//  camera:           red, green, blue, intensity, hue, hue_distance (paper Fig. 3)
//  laser:            distance, remission (paper Fig. 3)
//  camera (derived): grad_mag, grad_0 .. grad_5 (channel_layers.h, from intensity)
//  laser (derived):  height, distance_grad (channel_layers.h, from the distance layer)

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::fusion {

enum class LayerSource { camera, laser, cameraDerived, laserDerived, unknown };

LayerSource layerSource(std::string_view layer);
std::string toString(LayerSource source);  // "camera", "laser", "camera (derived)", ...

// The paper's seven pool layers (hue enters as hue_distance) and the channels
// `ProjectionConfig::extraChannels` adds, in table order.
const std::vector<std::string>& paperPoolLayers();
const std::vector<std::string>& extraChannelLayers();

// Shares per layer summed per source (keys: toString of the source); sources without a layer in
// `shares` are absent. Unknown layer names sum under "other".
std::map<std::string, double> sharesBySource(const std::map<std::string, double>& shares);

}  // namespace fusedet::fusion
