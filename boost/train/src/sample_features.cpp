// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/sample_features.h"
#include "fusedet/boost/parallel_for.h"

#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <numeric>
#include <stdexcept>

namespace fusedet::boosting {

SampleFeatures::SampleFeatures(const TrainingStacks& stacks, std::span<const Feature> pool,
                               std::span<const Sample> samples)
    : stacks_(stacks), pool_(pool), samples_(samples) {
  const std::size_t n = samples.size();
  // Layer count of the samples' own stacks (in a sharded job other ranks' stacks are empty).
  layers_ = n ? stacks.integrals(samples[0].stack).size() : 0;
  windows_.resize(n * layers_);
  for (std::size_t i = 0; i < n; ++i) {
    const IntegralStack& is = stacks.integrals(samples[i].stack);
    if (is.size() != layers_) throw std::invalid_argument("SampleFeatures: stacks differ in layer count");
    for (std::size_t l = 0; l < layers_; ++l)
      windows_[i * layers_ + l] = layerWindow(is.layer(l), is.width(), is.height(), samples[i].window);
  }
  auto sizeLess = [&](std::size_t a, std::size_t b) {
    for (std::size_t l = 0; l < layers_; ++l) {
      const LayerWindow &wa = windows_[a * layers_ + l], &wb = windows_[b * layers_ + l];
      if (wa.w != wb.w) return wa.w < wb.w;
      if (wa.h != wb.h) return wa.h < wb.h;
    }
    return false;
  };
  order_.resize(n);
  std::iota(order_.begin(), order_.end(), std::size_t{0});
  std::stable_sort(order_.begin(), order_.end(), sizeLess);
  for (std::size_t k = 0; k < n; ++k)
    if (k == 0 || sizeLess(order_[k - 1], order_[k])) runStart_.push_back(k);
  runStart_.push_back(n);
}

void SampleFeatures::block(std::size_t first, std::size_t count, std::span<float> out) const {
  block(first, count, out, samples_.size(), 0);
}

void SampleFeatures::block(std::size_t first, std::size_t count, std::span<float> out, std::size_t rowStride,
                           std::size_t column0) const {
  float* const dst = out.data() + column0;
  std::vector<FeatureLayout> layouts(count);
  for (std::size_t r = 0; r + 1 < runStart_.size(); ++r) {
    // Layouts relative to the window origin, shared by the whole group (layoutFeature is
    // translation invariant: it only uses differences of the outer rectangle's edges).
    const std::size_t rep = order_[runStart_[r]];
    for (std::size_t k = 0; k < count; ++k) {
      const Feature& f = pool_[first + k];
      const LayerWindow& lw = windows_[rep * layers_ + static_cast<std::size_t>(f.layer)];
      layouts[k] = layoutFeature(f.type, featureRectInWindow(f, lw.w, lw.h));
    }
    for (std::size_t q = runStart_[r]; q < runStart_[r + 1]; ++q) {
      const std::size_t i = order_[q];
      const IntegralStack& is = stacks_.integrals(samples_[i].stack);
      for (std::size_t k = 0; k < count; ++k) {
        const auto layer = static_cast<std::size_t>(pool_[first + k].layer);
        const LayerIntegral& li = is.layer(layer);
        const LayerWindow& lw = windows_[i * layers_ + layer];
        const FeatureLayout& l = layouts[k];
        // Same arithmetic, in the same order, as featureValue().
        auto rs = [&](int j) {
          const PixelRect& p = l.rects[static_cast<std::size_t>(j)];
          return li.rectSum(p.x0 + lw.x, p.y0 + lw.y, p.x1 + lw.x, p.y1 + lw.y);
        };
        const double black = l.blackCount == 2 ? rs(0) + rs(1) : rs(0);
        const double last = rs(l.blackCount);
        const double white = l.whiteIsRest ? last - black : last;
        dst[k * rowStride + i] = static_cast<float>(black / l.blackArea - white / l.whiteArea);
      }
    }
  }
}

void SampleFeatures::feature(std::size_t f, std::span<float> out) const {
  for (std::size_t i = 0; i < samples_.size(); ++i)
    out[i] = featureValue(stacks_.integrals(samples_[i].stack), pool_[f], samples_[i].window);
}

PositiveFeatures::PositiveFeatures(const TrainingStacks& stacks, std::span<const Feature> pool, int threads)
    : values_(pool.size() * stacks.positives().size()), positives_(stacks.positives().size()) {
  const SampleFeatures values(stacks, pool, stacks.positives());
  constexpr std::size_t kBlock = 1024;
  const std::size_t blocks = (pool.size() + kBlock - 1) / kBlock;
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    parallelFor(tbb::blocked_range<std::size_t>(0, blocks, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t b = r.begin(); b != r.end(); ++b) {
        const std::size_t first = b * kBlock, count = std::min(kBlock, pool.size() - first);
        values.block(first, count, std::span<float>(values_).subspan(first * positives_, count * positives_));
      }
    });
  });
}

StageFeatures::StageFeatures(const PositiveFeatures& positives, std::span<const std::size_t> accepted,
                             const TrainingStacks& stacks, std::span<const Feature> pool,
                             std::span<const Sample> negatives)
    : positives_(positives), accepted_(accepted), negatives_(negatives), negativeValues_(stacks, pool, negatives) {}

void StageFeatures::block(std::size_t first, std::size_t count, std::span<float> out) const {
  const std::size_t n = samples(), p = accepted_.size();
  for (std::size_t k = 0; k < count; ++k) {
    const float* cached = positives_.feature(first + k);
    float* row = out.data() + k * n;
    for (std::size_t i = 0; i < p; ++i) row[i] = cached[accepted_[i]];
  }
  negativeValues_.block(first, count, out, n, p);
}

void StageFeatures::feature(std::size_t f, std::span<float> out) const {
  const std::size_t p = accepted_.size();
  const float* cached = positives_.feature(f);
  for (std::size_t i = 0; i < p; ++i) out[i] = cached[accepted_[i]];
  negativeValues_.feature(f, out.subspan(p));
}

}  // namespace fusedet::boosting
