// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/data_split.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <stdexcept>

namespace fusedet::boosting {
namespace {

// One seeded Fisher-Yates shuffle per (seed, fold's test groups): prefixes of it are nested subsets.
template <typename T>
void shuffleForFold(std::vector<T>& v, const Fold& fold, std::uint64_t seed) {
  std::uint64_t h = seed * 0x9E3779B97F4A7C15ull;
  for (const std::string& t : fold.testGroups)
    for (char c : t) h = (h ^ static_cast<unsigned char>(c)) * 0x100000001B3ull;
  std::mt19937_64 rng(h);
  for (std::size_t i = v.size(); i > 1; --i) std::swap(v[i - 1], v[rng() % i]);
}

}  // namespace

std::size_t firstTestFrame(std::size_t frames, double trainFraction) {
  return static_cast<std::size_t>(std::lround(static_cast<double>(frames) * trainFraction));
}

Split splitByFrame(const std::vector<DatasetEntry>& entries, double trainFraction,
                   const std::set<std::string>& trainOnly) {
  if (!(trainFraction >= 0 && trainFraction <= 1))
    throw std::invalid_argument("train fraction must be in [0, 1]");
  // Groups in order of first appearance; items keep manifest order inside a group.
  std::vector<std::string> groups;
  std::map<std::string, std::vector<DatasetEntry>> byGroup;
  for (const DatasetEntry& e : entries) {
    auto [it, fresh] = byGroup.try_emplace(e.group);
    if (fresh) groups.push_back(e.group);
    it->second.push_back(e);
  }
  Split split;
  for (const std::string& g : groups) {
    const auto& items = byGroup[g];
    const std::size_t nTrain = trainOnly.count(g) ? items.size() : firstTestFrame(items.size(), trainFraction);
    for (std::size_t i = 0; i < items.size(); ++i) (i < nTrain ? split.train : split.test).push_back(items[i]);
  }
  return split;
}

std::vector<Fold> crossGroupFolds(const std::vector<std::string>& groupOfItem, std::size_t folds) {
  const std::set<std::string> groups(groupOfItem.begin(), groupOfItem.end());
  if (groups.size() < 2) throw std::invalid_argument("cross-group folds need at least 2 groups");
  const std::size_t k = folds == 0 || folds >= groups.size() ? groups.size() : folds;
  if (k < 2) throw std::invalid_argument("cross-group folds: at least 2 folds");
  std::map<std::string, std::size_t> foldOf;
  std::size_t g = 0;
  for (const std::string& name : groups) foldOf[name] = g++ % k;  // sorted by name
  std::vector<Fold> out(k);
  for (const auto& [name, f] : foldOf) out[f].testGroups.push_back(name);
  for (std::size_t i = 0; i < groupOfItem.size(); ++i)
    for (std::size_t f = 0; f < k; ++f) (foldOf[groupOfItem[i]] == f ? out[f].test : out[f].train).push_back(i);
  return out;
}

std::size_t trainingGroupCount(const Fold& fold, const std::vector<std::string>& groupOfItem) {
  std::set<std::string> g;
  for (std::size_t i : fold.train) g.insert(groupOfItem.at(i));
  return g.size();
}

Fold learningPositivesFold(const Fold& fold, const std::vector<std::size_t>& positivesOfItem,
                           std::size_t minPositives, std::uint64_t seed) {
  std::size_t total = 0;
  for (std::size_t i : fold.train) total += positivesOfItem.at(i);
  if (minPositives == 0 || minPositives >= total) return fold;
  std::vector<std::size_t> order = fold.train;
  shuffleForFold(order, fold, seed);
  Fold out;
  out.testGroups = fold.testGroups;
  out.test = fold.test;
  std::size_t held = 0;
  for (std::size_t k = 0; k < order.size() && held < minPositives; ++k) {
    out.train.push_back(order[k]);
    held += positivesOfItem.at(order[k]);
  }
  std::sort(out.train.begin(), out.train.end());
  return out;
}

Fold learningCurveFold(const Fold& fold, const std::vector<std::string>& groupOfItem, std::size_t groups,
                       std::uint64_t seed) {
  std::vector<std::string> names;
  for (std::size_t i : fold.train)
    if (std::find(names.begin(), names.end(), groupOfItem.at(i)) == names.end()) names.push_back(groupOfItem.at(i));
  if (groups >= names.size()) return fold;
  std::sort(names.begin(), names.end());
  shuffleForFold(names, fold, seed);
  const std::set<std::string> keep(names.begin(), names.begin() + static_cast<std::ptrdiff_t>(groups));
  Fold out;
  out.testGroups = fold.testGroups;
  out.test = fold.test;
  for (std::size_t i : fold.train)
    if (keep.count(groupOfItem.at(i))) out.train.push_back(i);
  return out;
}

}  // namespace fusedet::boosting
