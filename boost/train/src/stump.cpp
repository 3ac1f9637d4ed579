// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/stump.h"
#include "fusedet/boost/parallel_for.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numeric>
#include <stdexcept>
#include <string>

namespace fusedet::boosting {

namespace {

constexpr int kBins = FeatureMatrix::kMaxBins;
constexpr int kLanes = 4;  // independent sub-histograms: repeated bins do not serialise the adds

// Adds weights[i] into hist[i % 4][bins[i]] for i in [begin, end).
inline void accumulate(const std::uint8_t* bins, const float* w, std::size_t begin, std::size_t end,
                       float (*hist)[kBins]) {
  std::size_t i = begin;
  for (; i + 4 <= end; i += 4) {
    hist[0][bins[i]] += w[i];
    hist[1][bins[i + 1]] += w[i + 1];
    hist[2][bins[i + 2]] += w[i + 2];
    hist[3][bins[i + 3]] += w[i + 3];
  }
  for (; i < end; ++i) hist[0][bins[i]] += w[i];
}

// Two features in one pass: the weight is loaded once for both scatters (a quarter fewer
// loads per entry than one feature at a time).
inline void accumulatePair(const std::uint8_t* b0, const std::uint8_t* b1, const float* w, std::size_t begin,
                           std::size_t end, float (*h0)[kBins], float (*h1)[kBins]) {
  std::size_t i = begin;
  for (; i + 4 <= end; i += 4) {
    const float w0 = w[i], w1 = w[i + 1], w2 = w[i + 2], w3 = w[i + 3];
    h0[0][b0[i]] += w0;
    h1[0][b1[i]] += w0;
    h0[1][b0[i + 1]] += w1;
    h1[1][b1[i + 1]] += w1;
    h0[2][b0[i + 2]] += w2;
    h1[2][b1[i + 2]] += w2;
    h0[3][b0[i + 3]] += w3;
    h1[3][b1[i + 3]] += w3;
  }
  for (; i < end; ++i) {
    h0[0][b0[i]] += w[i];
    h1[0][b1[i]] += w[i];
  }
}

// Best split of one feature's histogram (pos/neg weight per bin), or gain -1 if none; leaves the
// histogram zeroed for the next feature. Four bins at a time with SSE2 (part of x86-64, so no
// target flags): lane merge, prefix sums, gains and the running argmax. Gains in float only rank
// candidates; the best are refined exactly in double. Ties: the smaller bin.
SplitCandidate scanBins(std::size_t feature, float (*pos)[kBins], float (*neg)[kBins]) {
#if defined(__SSE2__)
  const __m128 zero = _mm_setzero_ps();
  // Totals first (the gains need them).
  __m128 tp = zero, tn = zero;
  for (int b = 0; b < kBins; b += 4) {
    for (int l = 0; l < kLanes; ++l) {
      tp = _mm_add_ps(tp, _mm_load_ps(&pos[l][b]));
      tn = _mm_add_ps(tn, _mm_load_ps(&neg[l][b]));
    }
  }
  alignas(16) float t[4];
  _mm_store_ps(t, tp);
  const float totP = (t[0] + t[1]) + (t[2] + t[3]);
  _mm_store_ps(t, tn);
  const float totN = (t[0] + t[1]) + (t[2] + t[3]);
  const float tot = totP + totN, totS = totP - totN;
  const __m128 vtot = _mm_set1_ps(tot), vtotS = _mm_set1_ps(totS), eps = _mm_set1_ps(1e-6f * tot);
  const __m128 minusOne = _mm_set1_ps(-1.f);
  __m128 carryP = zero, carryN = zero;
  __m128 bestG = minusOne;
  __m128i bestI = _mm_setzero_si128();
  __m128i idx = _mm_set_epi32(3, 2, 1, 0);
  const __m128i four = _mm_set1_epi32(4);
  for (int b = 0; b < kBins; b += 4) {
    __m128 p = _mm_add_ps(_mm_add_ps(_mm_load_ps(&pos[0][b]), _mm_load_ps(&pos[1][b])),
                          _mm_add_ps(_mm_load_ps(&pos[2][b]), _mm_load_ps(&pos[3][b])));
    __m128 q = _mm_add_ps(_mm_add_ps(_mm_load_ps(&neg[0][b]), _mm_load_ps(&neg[1][b])),
                          _mm_add_ps(_mm_load_ps(&neg[2][b]), _mm_load_ps(&neg[3][b])));
    for (int l = 0; l < kLanes; ++l) {
      _mm_store_ps(&pos[l][b], zero);
      _mm_store_ps(&neg[l][b], zero);
    }
    // In-register prefix sums, plus the carry from the previous four bins.
    p = _mm_add_ps(p, _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(p), 4)));
    p = _mm_add_ps(p, _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(p), 8)));
    q = _mm_add_ps(q, _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(q), 4)));
    q = _mm_add_ps(q, _mm_castsi128_ps(_mm_slli_si128(_mm_castps_si128(q), 8)));
    p = _mm_add_ps(p, carryP);
    q = _mm_add_ps(q, carryN);
    carryP = _mm_shuffle_ps(p, p, _MM_SHUFFLE(3, 3, 3, 3));
    carryN = _mm_shuffle_ps(q, q, _MM_SHUFFLE(3, 3, 3, 3));
    const __m128 wl = _mm_add_ps(p, q), wr = _mm_sub_ps(vtot, wl);
    const __m128 sl = _mm_sub_ps(p, q), sr = _mm_sub_ps(vtotS, sl);
    const __m128 ok = _mm_and_ps(_mm_cmpgt_ps(wl, eps), _mm_cmpgt_ps(wr, eps));
    const __m128 one = _mm_set1_ps(1.f);
    const __m128 dl = _mm_or_ps(_mm_and_ps(ok, wl), _mm_andnot_ps(ok, one));
    const __m128 dr = _mm_or_ps(_mm_and_ps(ok, wr), _mm_andnot_ps(ok, one));
    __m128 g = _mm_add_ps(_mm_div_ps(_mm_mul_ps(sl, sl), dl), _mm_div_ps(_mm_mul_ps(sr, sr), dr));
    g = _mm_or_ps(_mm_and_ps(ok, g), _mm_andnot_ps(ok, minusOne));
    // Strictly greater only: within a lane the earlier (smaller) bin keeps a tie.
    const __m128 gt = _mm_cmpgt_ps(g, bestG);
    bestG = _mm_or_ps(_mm_and_ps(gt, g), _mm_andnot_ps(gt, bestG));
    const __m128i gti = _mm_castps_si128(gt);
    bestI = _mm_or_si128(_mm_and_si128(gti, idx), _mm_andnot_si128(gti, bestI));
    idx = _mm_add_epi32(idx, four);
  }
  alignas(16) float g4[4];
  alignas(16) std::int32_t i4[4];
  _mm_store_ps(g4, bestG);
  _mm_store_si128(reinterpret_cast<__m128i*>(i4), bestI);
  SplitCandidate best{feature, 0, -1};
  for (int l = 0; l < 4; ++l) {
    // The split after the last bin puts everything left: not a split.
    if (i4[l] >= kBins - 1) continue;
    if (g4[l] > best.gain || (g4[l] == best.gain && g4[l] >= 0 && i4[l] < best.bin))
      best = {feature, i4[l], double(g4[l])};
  }
  return best;
#else
  alignas(64) float wp[kBins], wn[kBins], gain[kBins];
  for (int b = 0; b < kBins; ++b) {
    wp[b] = (pos[0][b] + pos[1][b]) + (pos[2][b] + pos[3][b]);
    wn[b] = (neg[0][b] + neg[1][b]) + (neg[2][b] + neg[3][b]);
    for (int l = 0; l < kLanes; ++l) pos[l][b] = neg[l][b] = 0.f;
  }
  float cp = 0, cn = 0;
  for (int b = 0; b < kBins; ++b) {
    cp += wp[b];
    cn += wn[b];
    wp[b] = cp;
    wn[b] = cn;
  }
  const float tot = cp + cn, totS = cp - cn;
  for (int b = 0; b < kBins; ++b) {
    const float wl = wp[b] + wn[b], wr = tot - wl;
    const float sl = wp[b] - wn[b], sr = totS - sl;
    const bool ok = wl > 1e-6f * tot && wr > 1e-6f * tot;
    gain[b] = ok ? sl * sl / wl + sr * sr / wr : -1.f;
  }
  SplitCandidate best{feature, 0, -1};
  for (int b = 0; b < kBins - 1; ++b)
    if (gain[b] > best.gain) best = {feature, b, double(gain[b])};
  return best;
#endif
}

}  // namespace

bool betterSplit(const SplitCandidate& a, const SplitCandidate& b) {
  if (a.gain != b.gain) return a.gain > b.gain;
  if (a.feature != b.feature) return a.feature < b.feature;
  return a.bin < b.bin;
}

void keepBestSplits(std::vector<SplitCandidate>& top, const SplitCandidate& c, std::size_t k) {
  if (top.size() == k && !betterSplit(c, top.back())) return;
  top.insert(std::upper_bound(top.begin(), top.end(), c, betterSplit), c);
  if (top.size() > k) top.pop_back();
}

std::vector<std::size_t> refineOrder(const std::vector<SplitCandidate>& candidates) {
  std::vector<std::size_t> features;
  for (const auto& c : candidates) features.push_back(c.feature);
  if (features.empty()) features.push_back(0);
  std::sort(features.begin(), features.end());
  return features;
}

std::vector<SplitCandidate> bestBinnedSplits(const FeatureMatrix& m, std::size_t positives,
                                             std::span<const float> weights, std::size_t k,
                                             int threads) {
  const std::size_t n = m.samples();
  if (weights.size() != n || positives > n)
    throw std::invalid_argument("bestBinnedSplits: " + std::to_string(weights.size()) +
                                " weights / " + std::to_string(positives) + " positives for " +
                                std::to_string(n) + " samples");
  k = std::max<std::size_t>(1, k);
  constexpr std::size_t kChunk = 256;
  const std::size_t chunks = (m.features() + kChunk - 1) / kChunk;
  std::vector<std::vector<SplitCandidate>> perChunk(chunks);
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    parallelFor(tbb::blocked_range<std::size_t>(0, chunks, 1),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        alignas(64) float pos[2][kLanes][kBins];
                        alignas(64) float neg[2][kLanes][kBins];
                        std::memset(pos, 0, sizeof pos);  // scanBins() re-zeroes what it reads
                        std::memset(neg, 0, sizeof neg);
                        for (std::size_t c = r.begin(); c != r.end(); ++c) {
                          std::vector<SplitCandidate> top;
                          const std::size_t end = std::min(m.features(), (c + 1) * kChunk);
                          std::size_t f = c * kChunk;
                          for (; f + 1 < end; f += 2) {
                            const std::uint8_t *b0 = m.row(f), *b1 = m.row(f + 1);
                            accumulatePair(b0, b1, weights.data(), 0, positives, pos[0], pos[1]);
                            accumulatePair(b0, b1, weights.data(), positives, n, neg[0], neg[1]);
                            for (int q = 0; q < 2; ++q) {
                              const SplitCandidate s = scanBins(f + std::size_t(q), pos[q], neg[q]);
                              if (s.gain >= 0) keepBestSplits(top, s, k);
                            }
                          }
                          if (f < end) {
                            accumulate(m.row(f), weights.data(), 0, positives, pos[0]);
                            accumulate(m.row(f), weights.data(), positives, n, neg[0]);
                            const SplitCandidate s = scanBins(f, pos[0], neg[0]);
                            if (s.gain >= 0) keepBestSplits(top, s, k);
                          }
                          perChunk[c] = std::move(top);
                        }
                      });
  });
  std::vector<SplitCandidate> top;
  for (const auto& chunk : perChunk)
    for (const SplitCandidate& s : chunk) keepBestSplits(top, s, k);
  return top;
}

FittedStump fitStumpExact(std::size_t feature, std::span<const float> values,
                          std::span<const float> weights, std::size_t positives) {
  const std::size_t n = values.size();
  if (weights.size() != n || positives > n)
    throw std::invalid_argument("fitStumpExact: sizes of values, weights and positives differ");
  std::vector<std::uint32_t> order(n);
  std::iota(order.begin(), order.end(), 0u);
  // NaN sorts last (and goes right: NaN < threshold is false).
  std::stable_sort(order.begin(), order.end(), [&](std::uint32_t a, std::uint32_t b) {
    const float va = values[a], vb = values[b];
    if (std::isnan(vb)) return !std::isnan(va);
    return va < vb;
  });
  double tot = 0, totS = 0;
  for (std::size_t i = 0; i < n; ++i) {
    tot += weights[i];
    totS += i < positives ? weights[i] : -double(weights[i]);
  }
  FittedStump best;
  best.feature = feature;
  const double mean = tot > 0 ? totS / tot : 0;
  best.left = best.right = mean;  // no split: constant stump
  double bestGain = tot > 0 ? totS * totS / tot : 0;
  double wl = 0, sl = 0;
  for (std::size_t k = 0; k + 1 < n; ++k) {
    const std::uint32_t i = order[k];
    wl += weights[i];
    sl += i < positives ? weights[i] : -double(weights[i]);
    const float a = values[i], b = values[order[k + 1]];
    if (!(b > a)) continue;  // equal values (or NaN) cannot be separated
    const double wr = tot - wl, sr = totS - sl;
    if (wl <= 0 || wr <= 0) continue;
    const double gain = sl * sl / wl + sr * sr / wr;
    if (gain > bestGain) {
      bestGain = gain;
      float t = static_cast<float>((double(a) + double(b)) / 2);
      if (!(t > a)) t = b;  // adjacent floats: the midpoint rounds onto a
      best.threshold = t;
      best.left = sl / wl;
      best.right = sr / wr;
    }
  }
  best.error = std::max(0.0, tot - bestGain);
  return best;
}

double stumpSquaredError(const FittedStump& s, std::span<const float> values,
                         std::span<const float> weights, std::size_t positives) {
  double e = 0;
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double y = i < positives ? 1.0 : -1.0;
    const double d = y - s(values[i]);
    e += weights[i] * d * d;
  }
  return e;
}

FittedStump findBestStump(const FeatureMatrix& m, std::size_t positives,
                          std::span<const float> weights, const FeatureValuesFn& rawValues,
                          const StumpSearchOptions& options) {
  if (m.features() == 0 || m.samples() == 0)
    throw std::invalid_argument("findBestStump: empty feature matrix");
  const auto candidates =
      bestBinnedSplits(m, positives, weights, options.refineTop, options.threads);
  std::vector<float> values(m.samples());
  FittedStump best;
  bool have = false;
  for (std::size_t f : refineOrder(candidates)) {
    rawValues(f, values);
    const FittedStump s = fitStumpExact(f, values, weights, positives);
    if (!have || s.error < best.error) {
      best = s;
      have = true;
    }
  }
  return best;
}

}  // namespace fusedet::boosting
