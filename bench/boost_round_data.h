// SPDX-License-Identifier: Apache-2.0
#pragma once
// The precomputed feature matrix the boost_round benchmark hands to all three learners.

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace bench {

struct RoundData {
  std::size_t features = 0, samples = 0, positives = 0;  // samples [0, positives) are positives
  std::vector<float> values;                              // row-major: samples x features
  std::string description;
};

// Deterministic synthetic matrix: every feature mixes two of 64 latent per-sample factors plus
// noise; positives shift eight factors, so a few hundred features carry signal (as Haar features
// on real windows do) and the rest are noise. Needs no data.
inline RoundData syntheticRoundData(std::size_t features, std::size_t samples) {
  RoundData d;
  d.features = features;
  d.samples = samples;
  d.positives = samples / 3;
  d.description = "synthetic";
  constexpr int kLatent = 64;
  auto hash = [](std::uint64_t x) {  // splitmix64
    x += 0x9e3779b97f4a7c15ULL;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
    return x ^ (x >> 31);
  };
  auto uniform = [&](std::uint64_t key) { return float(hash(key) >> 40) / float(1 << 24) - 0.5f; };
  std::vector<float> z(samples * kLatent);
  for (std::size_t i = 0; i < samples; ++i)
    for (int k = 0; k < kLatent; ++k)
      z[i * kLatent + k] = uniform(i * 131 + k) + uniform(i * 131 + k + 77777) +
                           ((i < d.positives && k < 8) ? 0.3f * float(k + 1) / 8 : 0.f);
  d.values.resize(features * samples);
  for (std::size_t f = 0; f < features; ++f) {
    const std::uint64_t h = hash(f + 1000003);
    const int k1 = int(h % kLatent), k2 = int((h >> 8) % kLatent);
    const float a = uniform(h) * 4, b = uniform(h >> 3) * 2;
    for (std::size_t i = 0; i < samples; ++i)
      d.values[i * features + f] =
          a * z[i * kLatent + k1] + b * z[i * kLatent + k2] + 0.5f * uniform((f << 20) ^ i);
  }
  return d;
}

}  // namespace bench

// ---- Real features: OpenCV's default pool on KITTI windows ----
#include <algorithm>
#include <filesystem>
#include <opencv2/imgproc.hpp>

#include "fusedet/boost/feature_pool.h"
#include "fusedet/boost/sample_features.h"
#include "fusedet/boost/training_set.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace bench {

// Samples from the shared KITTI drives (intensity layer): the car boxes of moderate difficulty and
// their mirrored copies as positives (at most a third of the samples), label-free windows of the
// detector's scan as negatives (seeded reservoir sample). Features: the pool on a 24-unit grid with
// types a-e (OpenCV traincascade's BASIC set on 24x24: 162,336 features) - or, for other counts,
// the first `features` of the 24-grid pool with all ten types. `maxFrames` per drive (0 = all).
// The frames of the shared KITTI drives with their intensity layer and labels (`maxFrames` per
// drive, 0 = all); `keepPixels(i)` false leaves item i with labels and size only.
template <class KeepPixels>
std::vector<fusedet::DatasetItem> kittiIntensityItems(std::size_t maxFrames, KeepPixels keepPixels) {
  namespace fs = std::filesystem;
  using namespace fusedet;
  std::vector<DatasetItem> items;
  for (const char* drive : {"kitti_0009", "kitti"}) {
    const fs::path root = fs::path(FUSEDET_DATA_DIR) / drive;
    auto ids = fusion::listKittiFrames(root);
    if (maxFrames && ids.size() > maxFrames) ids.resize(maxFrames);
    for (const auto& id : ids) {
      const fusion::KittiFrame f = fusion::readKittiFrame(root, id);
      DatasetItem item;
      item.id = std::string(drive) + "/" + id;
      item.stack = LayerStack(f.image.cols, f.image.rows);
      if (keepPixels(items.size())) {
        cv::Mat gray;
        cv::cvtColor(f.image, gray, cv::COLOR_BGR2GRAY);
        item.stack.set(Layer{"intensity", gray, {}});
      }
      item.labels = f.labels;
      items.push_back(std::move(item));
    }
  }
  return items;
}

// The cascade whose (empty) scan yields the negatives: 24 px high, the positives' aspect ratio.
inline fusedet::boosting::Cascade negativeScan(const fusedet::boosting::TrainingStacks& stacks) {
  fusedet::boosting::Cascade scan;
  scan.layers = {"intensity"};
  scan.windowHeight = 24;
  scan.windowWidth = static_cast<int>(std::lround(24 * stacks.positiveAspect()));
  return scan;
}

// The grid-24 pool on `layers`: types a-e for 162,336 features (OpenCV's BASIC set), else the
// first `features` of all ten types.
inline std::vector<fusedet::boosting::Feature> roundPool(std::size_t features, const std::vector<std::string>& layers) {
  using namespace fusedet::boosting;
  PoolConfig pc;
  pc.grid = 24;
  pc.layers = layers;
  pc.types = features == 162336 ? parseFeatureTypes("a-e") : std::vector<FeatureType>{};
  std::vector<Feature> pool = generatePool(pc);
  if (pool.size() < features) throw std::runtime_error("pool has only " + std::to_string(pool.size()) + " features");
  pool.resize(features);
  return pool;
}

inline RoundData kittiRoundData(std::size_t features, std::size_t samples, std::size_t maxFrames = 0) {
  using namespace fusedet;
  using namespace fusedet::boosting;
  const std::vector<DatasetItem> items = kittiIntensityItems(maxFrames, [](std::size_t) { return true; });
  SampleConfig sc;
  sc.className = "car";
  sc.scan.scaleFactor = 1.25;
  const std::vector<std::string> layers = {"intensity"};
  const TrainingStacks stacks(items, layers, std::nullopt, sc);
  std::vector<Sample> all = stacks.positives();
  if (all.size() > samples / 3) all.resize(samples / 3);
  const std::size_t positives = all.size();
  const NegativeHarvest neg = stacks.harvestNegatives(negativeScan(stacks), samples - positives, 1, 0);
  all.insert(all.end(), neg.samples.begin(), neg.samples.end());
  const std::vector<Feature> pool = roundPool(features, layers);

  RoundData d;
  d.features = features;
  d.samples = all.size();
  d.positives = positives;
  d.description = "KITTI intensity windows (" + std::to_string(items.size()) + " frames, " +
                  std::to_string(positives) + " car boxes incl. mirrored, " +
                  std::to_string(all.size() - positives) + " label-free windows), grid-24 pool";
  d.values.resize(d.features * d.samples);
  const SampleFeatures sf(stacks, pool, all);
  constexpr std::size_t kBlock = 4096;
  std::vector<float> buf;
  for (std::size_t first = 0; first < features; first += kBlock) {
    const std::size_t count = std::min(kBlock, features - first);
    buf.resize(count * d.samples);
    sf.block(first, count, buf);
    for (std::size_t k = 0; k < count; ++k)
      for (std::size_t i = 0; i < d.samples; ++i) d.values[i * features + first + k] = buf[k * d.samples + i];
  }
  return d;
}

}  // namespace bench
