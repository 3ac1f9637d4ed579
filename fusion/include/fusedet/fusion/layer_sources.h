// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which sensor a layer of the joint feature pool comes from, so a cascade's weight share per layer
// can be summed per source: what each sensor contributes (issue 15).
//  camera: red, green, blue, intensity, hue, hue_distance (paper Fig. 3)
//  laser:  distance, remission (paper Fig. 3)
//  network: neural_<class> (a pretrained network's score layers, fusion/neural; issue 30)

#include <map>
#include <string>
#include <string_view>
#include <vector>

namespace fusedet::fusion {

enum class LayerSource { camera, laser, network, unknown };

LayerSource layerSource(std::string_view layer);
std::string toString(LayerSource source);  // "camera", "laser", "network", "other"

// The paper's seven pool layers (hue enters as hue_distance), in table order.
const std::vector<std::string>& paperPoolLayers();
// The network's score layers (fusion/neural/score_layers.h defaultScoreLayers), in its order.
const std::vector<std::string>& networkPoolLayers();

// Shares per layer summed per source (keys: toString of the source); sources without a layer in
// `shares` are absent. Unknown layer names sum under "other".
std::map<std::string, double> sharesBySource(const std::map<std::string, double>& shares);

}  // namespace fusedet::fusion
