// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/feature_type.h"

namespace fusedet::boosting {

namespace {
constexpr std::array<std::string_view, kFeatureTypeCount> kNames = {
    "edge_horizontal", "edge_vertical",     "line_horizontal",  "line_vertical",
    "checker",         "center_surround",   "corner_top_left",  "corner_top_right",
    "corner_bottom_left", "corner_bottom_right"};
}  // namespace

char toLetter(FeatureType type) { return static_cast<char>('a' + static_cast<int>(type)); }

std::optional<FeatureType> featureTypeFromLetter(char letter) {
  if (letter < 'a' || letter >= static_cast<char>('a' + kFeatureTypeCount)) return std::nullopt;
  return static_cast<FeatureType>(letter - 'a');
}

std::string_view toName(FeatureType type) { return kNames.at(static_cast<std::size_t>(type)); }

}  // namespace fusedet::boosting
