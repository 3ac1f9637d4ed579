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
