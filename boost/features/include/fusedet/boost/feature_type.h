// SPDX-License-Identifier: Apache-2.0
#pragma once
// The ten Haar-like feature types of the paper (Fig. 1): a-f standard (edge x2, line x2, four-square
// checker, centre-surround), g-j corner-like (2x2 quadrants, one quadrant against the other three).

#include <array>
#include <cstdint>
#include <optional>
#include <string_view>

namespace fusedet::boosting {

enum class FeatureType : std::uint8_t {
  kEdgeHorizontal = 0,  // a: left half vs right half
  kEdgeVertical,        // b: top half vs bottom half
  kLineHorizontal,      // c: three vertical stripes, middle vs outer
  kLineVertical,        // d: three horizontal stripes, middle vs outer
  kChecker,             // e: four squares, diagonal pairs
  kCenterSurround,      // f: centre vs surround
  kCornerTopLeft,       // g: top-left quadrant vs the other three
  kCornerTopRight,      // h
  kCornerBottomLeft,    // i
  kCornerBottomRight,   // j
};

inline constexpr std::size_t kFeatureTypeCount = 10;

// Letter used in the paper and in model files: 'a'..'j'.
char toLetter(FeatureType type);
std::optional<FeatureType> featureTypeFromLetter(char letter);
std::string_view toName(FeatureType type);  // e.g. "edge_horizontal"
inline bool isCorner(FeatureType type) { return type >= FeatureType::kCornerTopLeft; }

}  // namespace fusedet::boosting
