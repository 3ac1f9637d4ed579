// SPDX-License-Identifier: Apache-2.0
#pragma once
// The windows of a cascade trained on proposals (Cascade::windows == WindowSearch::kProposals):
// instead of scanning every position and scale, it is run on the boxes a detector network proposed
// on the stack (LayerStack::proposals, plain boxes with a class and a score; fusion/neural makes
// them) - the network proposes, the cascade over the joint pool decides (issue 30).
//
// The one rule of which windows such a cascade sees: the stack's proposals of the cascade's class
// scoring >= its proposalMinScore, each box cut to the stack's reference pixels, boxes under 2 px
// on a side after the cut left out, in the stack's order. Training takes its negatives here
// (training_set.h) and detection its windows, so both see the same windows.

#include <string>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/detector.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

struct ProposalWindow {
  Box box;  // reference pixels, inside the stack
  double score = 0;
};

std::vector<ProposalWindow> proposalWindows(const LayerStack& stack, const std::string& className, double minScore);

// Detections of a chain of proposal cascades (AND, chain_evaluation.h) on one stack: every window of
// proposalWindows() (the first cascade's class and minimum score) that every cascade accepts
// (evaluateWindow), with the proposal's box and score (the network's: it ranks them), the stack's
// stamp and id. No grouping: the network's NMS has run. `stats` (optional) counts windows and the
// stumps of evaluated stages. Throws std::invalid_argument when a cascade of the chain is not a
// proposal cascade, and what requireStackNetwork() throws.
std::vector<Detection> verifyProposals(const std::vector<const Cascade*>& chain, const LayerStack& stack,
                                       ScanStats* stats = nullptr);

}  // namespace fusedet::boosting
