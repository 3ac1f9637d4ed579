// SPDX-License-Identifier: Apache-2.0
#pragma once
// Sample selection of a sharded training job (cascade_trainer.h with a Collective): every rank
// works only on the stacks it owns (TrainingStacks' Shard) and the results are combined exactly,
// so every rank ends up with the same lists, and the same ones a one-rank job computes.

#include <cstddef>
#include <cstdint>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/collective.h"
#include "fusedet/boost/training_set.h"
#include "fusedet/core/dataset.h"

namespace fusedet::boosting {

// classReferenceHue() (cascade_trainer.h) of a sharded job: each rank adds the positives of its
// own items, the 36 pixel counts are summed over the ranks (integers: exact).
double shardedReferenceHue(const std::vector<DatasetItem>& items, const SampleConfig& samples, Shard shard,
                           Collective& job);

// TrainingStacks::harvestNegatives() of a sharded job: each rank scans its original stacks, the
// candidate counts per stack are summed, reservoirSlots() picks the global candidates, and the
// owners of the picked windows gather them to every rank. Same samples and counts as one rank.
NegativeHarvest shardedHarvest(const TrainingStacks& stacks, const Cascade& cascade, std::size_t wanted,
                               std::uint64_t seed, int threads, Collective& job);

// The positives `cascade` accepts, in positives() order (each rank evaluates its own), and their
// indices into positives().
std::vector<Sample> acceptedPositives(const TrainingStacks& stacks, const Cascade& cascade, Collective* job);
std::vector<std::size_t> acceptedPositiveIndices(const TrainingStacks& stacks, const Cascade& cascade,
                                                 Collective* job);

}  // namespace fusedet::boosting
