// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/proposal_windows.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fusedet/boost/integral_stack.h"

namespace fusedet::boosting {

namespace {
constexpr double kMinSide = 2;  // px after the cut
}

std::vector<ProposalWindow> proposalWindows(const LayerStack& stack, const std::string& className, double minScore) {
  std::vector<ProposalWindow> out;
  const double W = stack.width(), H = stack.height();
  for (const Detection& p : stack.proposals) {
    if (p.className != className || !(p.score >= minScore)) continue;
    const Box& b = p.box;
    if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.w) || !std::isfinite(b.h)) continue;
    const double x0 = std::clamp(b.x, 0.0, W), y0 = std::clamp(b.y, 0.0, H);
    const double x1 = std::clamp(b.x + b.w, 0.0, W), y1 = std::clamp(b.y + b.h, 0.0, H);
    if (x1 - x0 < kMinSide || y1 - y0 < kMinSide) continue;
    out.push_back(ProposalWindow{Box{x0, y0, x1 - x0, y1 - y0}, p.score});
  }
  return out;
}

std::vector<Detection> verifyProposals(const std::vector<const Cascade*>& chain, const LayerStack& stack,
                                       ScanStats* stats) {
  if (chain.empty()) throw std::invalid_argument("verifyProposals: no cascade given");
  for (const Cascade* c : chain)
    if (c->windows != WindowSearch::kProposals)
      throw std::invalid_argument((c->source.empty() ? c->className : c->source) +
                                  ": a sliding-window cascade cannot verify proposals");
  const Cascade& first = *chain.front();
  std::vector<ProposalWindow> windows = proposalWindows(stack, first.className, first.proposalMinScore);
  if (stats) {
    stats->windows += windows.size();
    stats->scales += 1;
  }
  for (const Cascade* c : chain) {
    if (windows.empty()) break;
    const IntegralStack integrals = integrateFor(*c, stack);
    std::vector<ProposalWindow> kept;
    for (const ProposalWindow& w : windows) {
      const WindowResult r = evaluateWindow(*c, integrals, w.box);
      if (stats)
        for (int s = 0; s < std::min<int>(r.stagesPassed + 1, static_cast<int>(c->stages.size())); ++s)
          stats->stumps += c->stages[static_cast<std::size_t>(s)].stumps.size();
      if (r.accepted) kept.push_back(w);
    }
    windows = std::move(kept);
  }
  std::vector<Detection> out;
  for (const ProposalWindow& w : windows) {
    Detection d;
    d.className = first.className;
    d.score = w.score;
    d.box = w.box;
    d.unitBox = stack.toUnit(w.box);
    d.stamp = stack.stamp;
    d.stackId = stack.id;
    out.push_back(std::move(d));
  }
  return out;
}

}  // namespace fusedet::boosting
