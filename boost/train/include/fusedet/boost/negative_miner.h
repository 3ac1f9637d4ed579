// SPDX-License-Identifier: Apache-2.0
#pragma once
// Negative mining for cascade training, incremental across stages. Every stage's bootstrapping
// asks for the label-free windows of the training stacks that the cascade so far still accepts
// (TrainingStacks::harvestNegatives() rescans every window of every stack with the whole cascade).
// A cascade only grows by appending stages, and a window rejected once stays rejected, so the
// miner keeps, per stack, the indices of the label-free windows every stage applied so far
// accepted, and evaluates only the newly appended stages on those. Which windows are label-free
// is decided once (the labels do not change between stages).
//
// Same windows, same order (scale, row, column; stack by stack), same reservoir draws, same
// counts as harvestNegatives(): the harvest is identical (tested against it on KITTI stacks), so
// trained models are byte-identical. Windows are evaluated with the same per-window arithmetic
// as Detector::scan(IntegralStack) (scalar_scan.h); threads share the stacks.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/training_set.h"

namespace fusedet::boosting {
struct ScaleWindows;
}

namespace fusedet::boosting {

class NegativeMiner {
 public:
  // Keeps a reference: `stacks` must outlive the miner. Scans the original stacks this process
  // holds (every stack for an unsharded TrainingStacks).
  explicit NegativeMiner(const TrainingStacks& stacks);
  ~NegativeMiner();

  // Equal to stacks.harvestNegatives(cascade, wanted, seed, threads). Stages of `cascade` that a
  // previous call already applied are not evaluated again; a cascade that is not an extension of
  // the previous call's (other window, layers, or changed stages) starts over.
  NegativeHarvest harvest(const Cascade& cascade, std::size_t wanted, std::uint64_t seed, int threads);

  // Label-free windows of original stack s accepted by the cascade of the last harvest, in scan
  // order, and all windows a full scan of stack s visits.
  std::vector<Box> candidateWindows(std::size_t s) const;
  std::size_t windowCount(std::size_t s) const { return windows_.at(s); }

 private:
  void update(const Cascade& cascade, int threads);
  bool extends(const Cascade& cascade) const;

  const TrainingStacks& stacks_;
  Cascade applied_;                              // window, layers and the stages applied so far
  bool started_ = false;
  std::vector<std::vector<std::uint32_t>> alive_;  // per original stack: window indices, scan order
  std::vector<std::size_t> windows_;             // per original stack: windows of a full scan
  std::vector<std::vector<ScaleWindows>> scales_;  // per original stack: the scan's windows
};

}  // namespace fusedet::boosting
