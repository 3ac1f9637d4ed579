// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/feature_matrix.h"
#include "fusedet/boost/parallel_for.h"

#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace fusedet::boosting {

FeatureMatrix::FeatureMatrix(std::size_t features, std::size_t samples)
    : bins_(features * samples), quantileBin_(samples), features_(features), samples_(samples) {
  // The quantile bin of each rank, once per matrix instead of a division per sample and feature.
  for (std::size_t p = 0; p < samples; ++p) quantileBin_[p] = static_cast<std::uint8_t>(p * kMaxBins / samples);
}

std::vector<float> binEdges(std::span<const float> values) {
  // Evenly strided subsample: deterministic, and enough for 255 quantiles.
  const std::size_t n = values.size();
  const std::size_t take = std::min(n, FeatureMatrix::kEdgeSample);
  std::vector<float> s;
  s.reserve(take);
  for (std::size_t k = 0; k < take; ++k) {
    const float v = values[k * n / take];
    if (!std::isnan(v)) s.push_back(v);
  }
  std::sort(s.begin(), s.end());
  std::vector<float> edges;
  if (s.empty()) return edges;
  const std::size_t unique =
      static_cast<std::size_t>(std::unique(s.begin(), s.end()) - s.begin());
  if (unique <= static_cast<std::size_t>(FeatureMatrix::kMaxBins)) {
    // Few distinct values: one bin per value, so no split is lost to quantisation.
    edges.assign(s.begin() + 1, s.begin() + static_cast<std::ptrdiff_t>(unique));
    return edges;
  }
  // Quantiles of the (de-duplicated) sorted sample; edges strictly increasing.
  edges.reserve(FeatureMatrix::kMaxBins - 1);
  for (int k = 1; k < FeatureMatrix::kMaxBins; ++k) {
    const float e = s[static_cast<std::size_t>(k) * unique / FeatureMatrix::kMaxBins];
    if (e > s[0] && (edges.empty() || e > edges.back())) edges.push_back(e);
  }
  return edges;
}

namespace {

// Order-preserving map of a float onto an unsigned key (NaN last).
inline std::uint32_t sortKey(float v) {
  if (std::isnan(v)) return 0xFFFFFFFFu;
  std::uint32_t u;
  std::memcpy(&u, &v, sizeof u);
  return (u & 0x80000000u) ? ~u : (u | 0x80000000u);
}

// Per-thread scratch of the radix sort.
struct RadixScratch {
  std::vector<std::uint32_t> key, key2, idx, idx2;
};

}  // namespace

void FeatureMatrix::setFeature(std::size_t f, std::span<const float> values) {
  if (f >= features_ || values.size() != samples_)
    throw std::out_of_range("FeatureMatrix::setFeature: feature or sample count out of range");
  const std::size_t n = samples_;
  if (n == 0) return;
  // Rank the samples with an LSD radix sort (4 passes of 8 bits, skipping passes where every key
  // has the same byte): O(n), about 4x cheaper than sorting a sample and binary-searching edges.
  thread_local RadixScratch s;
  s.key.resize(n);
  s.key2.resize(n);
  s.idx.resize(n);
  s.idx2.resize(n);
  // Keys and the counts of all four bytes in one pass over the values.
  std::array<std::array<std::uint32_t, 257>, 4> count{};
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t k = sortKey(values[i]);
    s.key[i] = k;
    s.idx[i] = static_cast<std::uint32_t>(i);
    ++count[0][(k & 0xFFu) + 1];
    ++count[1][((k >> 8) & 0xFFu) + 1];
    ++count[2][((k >> 16) & 0xFFu) + 1];
    ++count[3][(k >> 24) + 1];
  }
  for (int pass = 0; pass < 4; ++pass) {
    std::array<std::uint32_t, 257>& c = count[static_cast<std::size_t>(pass)];
    if (std::any_of(c.begin() + 1, c.end(), [n](std::uint32_t v) { return v == n; })) continue;
    for (int b = 0; b < 256; ++b) c[b + 1] += c[b];
    const int shift = 8 * pass;
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint32_t pos = c[(s.key[i] >> shift) & 0xFFu]++;
      s.key2[pos] = s.key[i];
      s.idx2[pos] = s.idx[i];
    }
    s.key.swap(s.key2);
    s.idx.swap(s.idx2);
  }
  // Bins along the sorted order: equal values share a bin, bins never decrease. With at most
  // kMaxBins distinct values each gets its own bin (nothing lost to quantisation); otherwise
  // bins are equal-count quantiles of all values (quantileBin_[p] = p * kMaxBins / n).
  std::size_t distinct = 1;
  for (std::size_t p = 1; p < n; ++p) distinct += s.key[p] != s.key[p - 1];
  std::uint8_t* out = bins_.data() + f * samples_;
  const bool ownBins = distinct <= static_cast<std::size_t>(kMaxBins);
  unsigned bin = 0;
  out[s.idx[0]] = 0;
  for (std::size_t p = 1; p < n; ++p) {
    if (s.key[p] != s.key[p - 1]) bin = ownBins ? bin + 1 : std::max<unsigned>(bin, quantileBin_[p]);
    out[s.idx[p]] = static_cast<std::uint8_t>(bin);
  }
}

void FeatureMatrix::setFeature(std::size_t f, std::span<const float> values, std::span<const float> edges) {
  if (f >= features_ || values.size() != samples_ || edges.size() >= static_cast<std::size_t>(kMaxBins))
    throw std::out_of_range("FeatureMatrix::setFeature: feature, sample or edge count out of range");
  std::uint8_t* out = bins_.data() + f * samples_;
  for (std::size_t i = 0; i < samples_; ++i) {
    const float v = values[i];
    const auto bin = std::isnan(v) ? edges.size()
                                   : static_cast<std::size_t>(std::upper_bound(edges.begin(), edges.end(), v) -
                                                              edges.begin());
    out[i] = static_cast<std::uint8_t>(bin);
  }
}

FeatureMatrix buildFeatureMatrix(std::size_t features, std::size_t samples,
                                 const FeatureBlockFn& values, int threads, std::size_t block) {
  FeatureMatrix m(features, samples);
  if (features == 0 || samples == 0) return m;
  block = std::max<std::size_t>(1, block);
  const std::size_t blocks = (features + block - 1) / block;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    parallelFor(tbb::blocked_range<std::size_t>(0, blocks, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        std::vector<float> buf;
                        for (std::size_t b = r.begin(); b != r.end(); ++b) {
                          const std::size_t first = b * block;
                          const std::size_t count = std::min(block, features - first);
                          buf.resize(count * samples);
                          values(first, count, buf);
                          for (std::size_t k = 0; k < count; ++k)
                            m.setFeature(first + k, std::span<const float>(buf).subspan(k * samples, samples));
                        }
                      });
  });
  return m;
}

}  // namespace fusedet::boosting
