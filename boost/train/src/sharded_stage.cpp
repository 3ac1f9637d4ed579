// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/sharded_stage.h"
#include "fusedet/boost/parallel_for.h"

#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace fusedet::boosting {

namespace {

constexpr int kBins = FeatureMatrix::kMaxBins;
constexpr double kFixedOne = 1073741824.0;  // 2^30: weights sum to 1, so every sum fits int32
constexpr std::size_t kValueBlock = 256;    // features evaluated per step of the matrix build
constexpr std::size_t kHistChunk = 1024;    // features per reduce-scatter

// Best binned split of one feature from exact integer histograms (positive and negative fixed-point
// weight per bin): the rule of the in-process search (stump.cpp) in double on exact sums.
SplitCandidate scanFixedPoint(std::size_t feature, const std::int32_t* pos, const std::int32_t* neg) {
  std::int64_t tp = 0, tn = 0;
  for (int b = 0; b < kBins; ++b) {
    tp += pos[b];
    tn += neg[b];
  }
  const double tot = double(tp + tn), totS = double(tp - tn);
  SplitCandidate best{feature, 0, -1};
  std::int64_t p = 0, q = 0;
  for (int b = 0; b + 1 < kBins; ++b) {
    p += pos[b];
    q += neg[b];
    const double wl = double(p + q), wr = tot - wl;
    if (!(wl > 1e-6 * tot && wr > 1e-6 * tot)) continue;
    const double sl = double(p - q), sr = totS - sl;
    const double gain = sl * sl / wl + sr * sr / wr;
    if (gain > best.gain) best = {feature, b, gain};
  }
  return best;
}

}  // namespace

namespace {

// Global indices of the samples on `rank`'s stacks, ascending.
std::vector<std::size_t> samplesOf(const TrainingStacks& stacks, const std::vector<Sample>& samples, int rank) {
  std::vector<std::size_t> out;
  for (std::size_t i = 0; i < samples.size(); ++i)
    if (stacks.owner(samples[i].stack) == rank) out.push_back(i);
  return out;
}

std::vector<Sample> pick(const std::vector<Sample>& samples, const std::vector<std::size_t>& indices) {
  std::vector<Sample> out;
  for (std::size_t i : indices) out.push_back(samples[i]);
  return out;
}

}  // namespace

ShardedStage::ShardedStage(const TrainingStacks& stacks, std::span<const Feature> pool, std::vector<Sample> samples,
                           std::size_t positives, Collective& job, int threads)
    : stacks_(stacks),
      pool_(pool),
      job_(job),
      threads_(threads),
      samples_(std::move(samples)),
      positives_(positives),
      local_(samplesOf(stacks, samples_, job.rank())),
      localSamples_(pick(samples_, local_)),
      localPositives_(static_cast<std::size_t>(
          std::lower_bound(local_.begin(), local_.end(), positives_) - local_.begin())),
      values_(stacks, pool, localSamples_) {
  for (int r = 0; r < job.size(); ++r) {
    const std::vector<std::size_t> of = samplesOf(stacks, samples_, r);
    rankOrder_.insert(rankOrder_.end(), of.begin(), of.end());
    rankCounts_.push_back(of.size());
  }
  buildMatrix();
}

void ShardedStage::buildMatrix() {
  const std::size_t n = samples_.size(), nLocal = local_.size(), features = pool_.size();
  matrix_ = FeatureMatrix(features, nLocal);
  // The global subsample the bin edges come from: binEdges()'s stride, in global sample order.
  const std::size_t take = std::min(n, FeatureMatrix::kEdgeSample);
  std::vector<std::size_t> subsample(take);
  for (std::size_t k = 0; k < take; ++k) subsample[k] = k * n / take;
  std::vector<std::size_t> mySub;  // positions in local_ of my subsample samples
  for (std::size_t k = 0, j = 0; k < take; ++k) {
    while (j < nLocal && local_[j] < subsample[k]) ++j;
    if (j < nLocal && local_[j] == subsample[k]) mySub.push_back(j);
  }
  // Where each gathered subsample value goes: ranks in order, each its own subsample ascending.
  std::vector<std::size_t> subRank;      // position in the subsample, in gathered order
  std::vector<std::size_t> subPerRank(static_cast<std::size_t>(job_.size()), 0);
  for (int r = 0; r < job_.size(); ++r)
    for (std::size_t k = 0; k < take; ++k)
      if (stacks_.owner(samples_[subsample[k]].stack) == r) {
        subRank.push_back(k);
        ++subPerRank[static_cast<std::size_t>(r)];
      }

  tbb::task_arena arena(threads_ > 0 ? threads_ : tbb::task_arena::automatic);
  std::vector<float> buf, sub;
  for (std::size_t first = 0; first < features; first += kValueBlock) {
    const std::size_t count = std::min(kValueBlock, features - first);
    buf.assign(count * nLocal, 0.f);
    arena.execute([&] {
      parallelFor(tbb::blocked_range<std::size_t>(0, count, 16), [&](const tbb::blocked_range<std::size_t>& r) {
        values_.block(first + r.begin(), r.size(), std::span<float>(buf).subspan(r.begin() * nLocal, r.size() * nLocal));
      });
    });
    sub.resize(count * mySub.size());
    for (std::size_t k = 0; k < count; ++k)
      for (std::size_t j = 0; j < mySub.size(); ++j) sub[k * mySub.size() + j] = buf[k * nLocal + mySub[j]];
    const std::vector<float> all = allGatherValues<float>(job_, sub);
    if (all.size() != count * take)
      throw std::runtime_error("sharded stage: gathered " + std::to_string(all.size()) + " subsample values, expected " +
                               std::to_string(count * take) + " (ranks disagree about the samples)");
    arena.execute([&] {
      parallelFor(tbb::blocked_range<std::size_t>(0, count), [&](const tbb::blocked_range<std::size_t>& r) {
        std::vector<float> global(take);
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          std::size_t at = 0, g = 0;
          for (std::size_t rank = 0; rank < subPerRank.size(); ++rank) {
            for (std::size_t j = 0; j < subPerRank[rank]; ++j) global[subRank[g + j]] = all[at + k * subPerRank[rank] + j];
            at += count * subPerRank[rank];
            g += subPerRank[rank];
          }
          const std::vector<float> edges = binEdges(global);
          matrix_.setFeature(first + k, std::span<const float>(buf).subspan(k * nLocal, nLocal), edges);
        }
      });
    });
  }
}

std::vector<std::vector<float>> ShardedStage::gatherValues(const std::vector<std::size_t>& features) {
  const std::size_t nLocal = local_.size(), nf = features.size();
  std::vector<float> mine(nf * nLocal);
  for (std::size_t k = 0; k < nf; ++k) values_.feature(features[k], std::span<float>(mine).subspan(k * nLocal, nLocal));
  const std::vector<float> all = allGatherValues<float>(job_, mine);
  if (all.size() != nf * samples_.size())
    throw std::runtime_error("sharded stage: gathered " + std::to_string(all.size()) + " values, expected " +
                             std::to_string(nf * samples_.size()));
  std::vector<std::vector<float>> out(nf, std::vector<float>(samples_.size()));
  std::size_t at = 0, g = 0;
  for (const std::size_t count : rankCounts_) {
    for (std::size_t k = 0; k < nf; ++k)
      for (std::size_t j = 0; j < count; ++j) out[k][rankOrder_[g + j]] = all[at + k * count + j];
    at += nf * count;
    g += count;
  }
  return out;
}

FittedStump ShardedStage::findStump(std::span<const float> weights, std::span<float> chosenValues,
                                    std::size_t refineTop) {
  const std::size_t n = samples_.size(), nLocal = local_.size(), features = pool_.size();
  if (weights.size() != n || chosenValues.size() != n)
    throw std::invalid_argument("ShardedStage::findStump: " + std::to_string(weights.size()) + " weights for " +
                                std::to_string(n) + " samples");
  if (features == 0 || n == 0) throw std::invalid_argument("ShardedStage::findStump: empty pool or no samples");
  refineTop = std::max<std::size_t>(1, refineTop);
  std::vector<std::int32_t> wq(nLocal);
  for (std::size_t j = 0; j < nLocal; ++j)
    wq[j] = static_cast<std::int32_t>(std::llround(double(weights[local_[j]]) * kFixedOne));

  const auto ranks = static_cast<std::size_t>(job_.size()), me = static_cast<std::size_t>(job_.rank());
  tbb::task_arena arena(threads_ > 0 ? threads_ : tbb::task_arena::automatic);
  std::vector<SplitCandidate> top;
  std::vector<std::int32_t> hist, mine;
  for (std::size_t first = 0; first < features; first += kHistChunk) {
    const std::size_t count = std::min(kHistChunk, features - first);
    hist.assign(count * 2 * kBins, 0);
    arena.execute([&] {
      parallelFor(tbb::blocked_range<std::size_t>(0, count, 8), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k != r.end(); ++k) {
          const std::uint8_t* bins = matrix_.row(first + k);
          std::int32_t* pos = hist.data() + k * 2 * kBins;
          std::int32_t* neg = pos + kBins;
          for (std::size_t j = 0; j < localPositives_; ++j) pos[bins[j]] += wq[j];
          for (std::size_t j = localPositives_; j < nLocal; ++j) neg[bins[j]] += wq[j];
        }
      });
    });
    // Rank r scans features [count * r / ranks, count * (r + 1) / ranks) of the chunk.
    std::vector<int> blockSizes(ranks);
    for (std::size_t r = 0; r < ranks; ++r)
      blockSizes[r] = static_cast<int>((count * (r + 1) / ranks - count * r / ranks) * 2 * kBins);
    const std::size_t myFirst = count * me / ranks, myCount = count * (me + 1) / ranks - myFirst;
    mine.resize(myCount * 2 * kBins);
    job_.reduceScatterSum(hist, blockSizes, mine);
    for (std::size_t k = 0; k < myCount; ++k) {
      const std::int32_t* pos = mine.data() + k * 2 * kBins;
      const SplitCandidate s = scanFixedPoint(first + myFirst + k, pos, pos + kBins);
      if (s.gain >= 0) keepBestSplits(top, s, refineTop);
    }
  }
  std::vector<SplitCandidate> best;
  for (const SplitCandidate& s : allGatherValues<SplitCandidate>(job_, top)) keepBestSplits(best, s, refineTop);

  // Exact refinement on the gathered raw values: the same computation on every rank.
  const std::vector<std::size_t> order = refineOrder(best);
  const std::vector<std::vector<float>> raw = gatherValues(order);
  FittedStump chosen;
  std::size_t chosenAt = 0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const FittedStump s = fitStumpExact(order[k], raw[k], weights, positives_);
    if (k == 0 || s.error < chosen.error) {
      chosen = s;
      chosenAt = k;
    }
  }
  std::copy(raw[chosenAt].begin(), raw[chosenAt].end(), chosenValues.begin());
  return chosen;
}

}  // namespace fusedet::boosting
