// SPDX-License-Identifier: Apache-2.0
#pragma once
// The joint feature pool (paper §2, §3.2): every feature type x position x size (including aspect
// ratio) on a grid over the unit square x every selected layer. A feature of type t with a
// gx x gy grid (feature.h: featureGrid) has cells of dx x dy grid units, so it covers
// gx*dx x gy*dy units at every position where it fits: the enumeration OpenCV's traincascade uses
// for its pixel grid (24 x 24 and types a-e give its 162,336 features), here in unit-square
// coordinates so the same pool works for any window aspect ratio and layer resolution.

#include <cstddef>
#include <string>
#include <vector>

#include "fusedet/boost/feature.h"
#include "fusedet/boost/feature_type.h"

namespace fusedet::boosting {

struct PoolConfig {
  int grid = 16;             // grid units per side of the unit square
  int positionStep = 1;      // positions every n units
  int minCellSize = 1;       // smallest cell (dx, dy) in units
  int sizeStep = 1;          // cell sizes minCellSize, minCellSize + sizeStep, ...
  std::vector<std::string> layers = {"intensity"};  // pool order = Cascade::layers order
  std::vector<FeatureType> types;                   // empty = all ten (a-j)

  // Throws std::invalid_argument for a grid < 2, steps < 1, no layers or duplicate layers.
  void validate() const;
};

// The pool, feature-major by layer, then type, then size, then position. Feature::layer indexes
// config.layers.
std::vector<Feature> generatePool(const PoolConfig& config);

// Number of features generatePool() would return (computed without building them).
std::size_t poolSize(const PoolConfig& config);
// Features of one type on one layer.
std::size_t poolSize(const PoolConfig& config, FeatureType type);

// Parses "abcdefghij"-style letter sets ("a-f", "g-j" and "all" too); throws
// std::invalid_argument naming the bad letter.
std::vector<FeatureType> parseFeatureTypes(const std::string& spec);

}  // namespace fusedet::boosting
