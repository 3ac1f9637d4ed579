// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/feature_pool.h"

#include <algorithm>
#include <set>
#include <stdexcept>

namespace fusedet::boosting {

namespace {

std::vector<FeatureType> typesOf(const PoolConfig& c) {
  if (!c.types.empty()) return c.types;
  std::vector<FeatureType> all;
  for (std::size_t t = 0; t < kFeatureTypeCount; ++t) all.push_back(static_cast<FeatureType>(t));
  return all;
}

// Calls fn(x, y, w, h) in grid units for every placement of `type`.
template <class Fn>
void forEachPlacement(const PoolConfig& c, FeatureType type, Fn&& fn) {
  const auto [gx, gy] = featureGrid(type);
  for (int dx = c.minCellSize; gx * dx <= c.grid; dx += c.sizeStep)
    for (int dy = c.minCellSize; gy * dy <= c.grid; dy += c.sizeStep)
      for (int y = 0; y + gy * dy <= c.grid; y += c.positionStep)
        for (int x = 0; x + gx * dx <= c.grid; x += c.positionStep) fn(x, y, gx * dx, gy * dy);
}

std::size_t countPlacements(const PoolConfig& c, FeatureType type) {
  // Closed form per axis: sum over cell sizes of the number of positions.
  const auto [gx, gy] = featureGrid(type);
  auto axis = [&](int g) {
    std::size_t n = 0;
    for (int d = c.minCellSize; g * d <= c.grid; d += c.sizeStep)
      n += static_cast<std::size_t>((c.grid - g * d) / c.positionStep + 1);
    return n;
  };
  return axis(gx) * axis(gy);
}

}  // namespace

void PoolConfig::validate() const {
  if (grid < 2) throw std::invalid_argument("feature pool: grid must be >= 2, got " + std::to_string(grid));
  if (positionStep < 1 || sizeStep < 1 || minCellSize < 1)
    throw std::invalid_argument("feature pool: position step, size step and minimum cell size must be >= 1");
  if (layers.empty()) throw std::invalid_argument("feature pool: no layers selected");
  std::set<std::string> seen;
  for (const auto& l : layers)
    if (!seen.insert(l).second) throw std::invalid_argument("feature pool: layer '" + l + "' selected twice");
  std::set<FeatureType> seenTypes;
  for (FeatureType t : types)
    if (!seenTypes.insert(t).second)
      throw std::invalid_argument(std::string("feature pool: type '") + toLetter(t) + "' selected twice");
}

std::size_t poolSize(const PoolConfig& c, FeatureType type) {
  c.validate();
  return countPlacements(c, type);
}

std::size_t poolSize(const PoolConfig& c) {
  c.validate();
  std::size_t perLayer = 0;
  for (FeatureType t : typesOf(c)) perLayer += countPlacements(c, t);
  return perLayer * c.layers.size();
}

std::vector<Feature> generatePool(const PoolConfig& c) {
  const std::size_t n = poolSize(c);
  std::vector<Feature> pool;
  pool.reserve(n);
  const double g = c.grid;
  for (std::size_t l = 0; l < c.layers.size(); ++l)
    for (FeatureType t : typesOf(c))
      forEachPlacement(c, t, [&](int x, int y, int w, int h) {
        pool.push_back(Feature{t, Box{x / g, y / g, w / g, h / g}, static_cast<int>(l)});
      });
  return pool;
}

std::vector<FeatureType> parseFeatureTypes(const std::string& spec) {
  if (spec == "all") return {};
  std::vector<FeatureType> out;
  auto add = [&](char ch) {
    const auto t = featureTypeFromLetter(ch);
    if (!t) throw std::invalid_argument("feature types '" + spec + "': '" + std::string(1, ch) +
                                        "' is not a feature type (a-j)");
    if (std::find(out.begin(), out.end(), *t) == out.end()) out.push_back(*t);
  };
  for (std::size_t i = 0; i < spec.size(); ++i) {
    const char ch = spec[i];
    if (ch == ',' || ch == ' ') continue;
    if (i + 2 < spec.size() && spec[i + 1] == '-') {
      const char to = spec[i + 2];
      if (to < ch) throw std::invalid_argument("feature types '" + spec + "': empty range");
      for (char c = ch; c <= to; ++c) add(c);
      i += 2;
    } else {
      add(ch);
    }
  }
  if (out.empty()) throw std::invalid_argument("feature types '" + spec + "': no type given");
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace fusedet::boosting
