#include "fusedet/boost/feature_matrix.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace fusedet::boosting {

FeatureMatrix::FeatureMatrix(std::size_t features, std::size_t samples)
    : bins_(features * samples), features_(features), samples_(samples) {}

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

void FeatureMatrix::setFeature(std::size_t f, std::span<const float> values) {
  if (f >= features_ || values.size() != samples_)
    throw std::out_of_range("FeatureMatrix::setFeature: feature or sample count out of range");
  const std::vector<float> edges = binEdges(values);
  // Padded to 256 so the branchless search below never reads past the end.
  std::array<float, kMaxBins> e;
  e.fill(std::numeric_limits<float>::infinity());
  std::copy(edges.begin(), edges.end(), e.begin());
  std::uint8_t* out = bins_.data() + f * samples_;
  for (std::size_t i = 0; i < samples_; ++i) {
    const float v = values[i];
    unsigned pos = 0;  // number of edges <= v (NaN compares false: bin 0)
    for (unsigned step = kMaxBins / 2; step > 0; step >>= 1)
      pos += (e[pos + step - 1] <= v) ? step : 0;
    out[i] = static_cast<std::uint8_t>(pos);
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
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, blocks, 1),
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
