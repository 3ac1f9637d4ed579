// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/sharded_samples.h"

#include <algorithm>
#include <stdexcept>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/reference_hue.h"

namespace fusedet::boosting {

double shardedReferenceHue(const std::vector<DatasetItem>& items, const SampleConfig& samples, Shard shard,
                           Collective& job) {
  HueHistogram mine, mineBackground;
  for (std::size_t i = 0; i < items.size(); ++i) {
    if (!shard.owns(i)) continue;
    try {
      for (const Label& l : items[i].labels)
        if (isPositiveLabel(l, samples)) mine.add(items[i].stack, l.box);
      mineBackground.addImage(items[i].stack);
    } catch (const std::out_of_range& e) {
      throw std::runtime_error("reference hue: item " + items[i].id + ": " + e.what());
    }
  }
  // Bins hold pixel counts (weight 1 each): integers, summed exactly in any order.
  std::vector<std::int64_t> counts(2 * kHueBins);
  for (int b = 0; b < kHueBins; ++b) {
    counts[static_cast<std::size_t>(b)] = static_cast<std::int64_t>(mine.bins()[b]);
    counts[static_cast<std::size_t>(kHueBins + b)] = static_cast<std::int64_t>(mineBackground.bins()[b]);
  }
  job.allReduceSum(counts);
  HueHistogram all, background;
  for (int b = 0; b < kHueBins; ++b) {
    const double centre = (b + 0.5) * (360.0 / kHueBins);
    if (const auto n = counts[static_cast<std::size_t>(b)]; n > 0) all.addHue(centre, double(n));
    if (const auto n = counts[static_cast<std::size_t>(kHueBins + b)]; n > 0) background.addHue(centre, double(n));
  }
  return all.distinctiveHue(background);
}

namespace {

// A picked negative on its way from the owning rank to every rank.
struct PickedWindow {
  std::uint64_t slot = 0;
  std::uint64_t stack = 0;
  Box box;
};

}  // namespace

NegativeHarvest shardedHarvest(const TrainingStacks& stacks, const Cascade& cascade, std::size_t wanted,
                               std::uint64_t seed, int threads, Collective& job) {
  const Detector detector = TrainingStacks::harvestDetector(cascade);
  const std::size_t nStacks = stacks.originalStacks();
  std::vector<std::vector<Box>> mine(nStacks);
  std::vector<std::int64_t> counts(2 * nStacks, 0);  // candidates per stack, then windows scanned
  for (std::size_t s = 0; s < nStacks; ++s) {
    if (stacks.owner(s) != job.rank()) continue;
    std::size_t scanned = 0;
    mine[s] = stacks.candidateWindows(detector, s, threads, &scanned);
    counts[s] = static_cast<std::int64_t>(mine[s].size());
    counts[nStacks + s] = static_cast<std::int64_t>(scanned);
  }
  job.allReduceSum(counts);
  NegativeHarvest h;
  std::vector<std::size_t> start(nStacks + 1, 0);  // first global candidate index of each stack
  for (std::size_t s = 0; s < nStacks; ++s) {
    start[s + 1] = start[s] + static_cast<std::size_t>(counts[s]);
    h.windowsScanned += static_cast<std::size_t>(counts[nStacks + s]);
  }
  h.candidates = start[nStacks];
  const std::vector<std::size_t> slots = reservoirSlots(h.candidates, wanted, seed);
  std::vector<PickedWindow> picked;
  for (std::size_t j = 0; j < slots.size(); ++j) {
    const auto s = static_cast<std::size_t>(std::upper_bound(start.begin(), start.end(), slots[j]) - start.begin()) - 1;
    if (stacks.owner(s) == job.rank()) picked.push_back(PickedWindow{j, s, mine[s][slots[j] - start[s]]});
  }
  const std::vector<PickedWindow> all = allGatherValues<PickedWindow>(job, picked);
  if (all.size() != slots.size())
    throw std::runtime_error("sharded harvest: " + std::to_string(all.size()) + " windows gathered for " +
                             std::to_string(slots.size()) + " picks (ranks disagree about the data)");
  h.samples.resize(slots.size());
  for (const PickedWindow& p : all) h.samples.at(p.slot) = Sample{static_cast<std::uint32_t>(p.stack), p.box};
  return h;
}

std::vector<std::size_t> acceptedPositiveIndices(const TrainingStacks& stacks, const Cascade& cascade,
                                                 Collective* job) {
  const std::vector<Sample>& all = stacks.positives();
  std::vector<std::int64_t> accepted(all.size(), cascade.stages.empty() ? 1 : 0);
  if (!cascade.stages.empty()) {
    for (std::size_t k = 0; k < all.size(); ++k) {
      if (job && stacks.owner(all[k].stack) != job->rank()) continue;
      accepted[k] = evaluateWindow(cascade, stacks.integrals(all[k].stack), all[k].window).accepted ? 1 : 0;
    }
    if (job) job->allReduceSum(accepted);
  }
  std::vector<std::size_t> out;
  for (std::size_t k = 0; k < all.size(); ++k)
    if (accepted[k]) out.push_back(k);
  return out;
}

std::vector<Sample> acceptedPositives(const TrainingStacks& stacks, const Cascade& cascade, Collective* job) {
  std::vector<Sample> out;
  for (std::size_t k : acceptedPositiveIndices(stacks, cascade, job)) out.push_back(stacks.positives()[k]);
  return out;
}

}  // namespace fusedet::boosting
