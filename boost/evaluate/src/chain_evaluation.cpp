// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/chain_evaluation.h"

#include <chrono>
#include <numeric>
#include <stdexcept>

#include "fusedet/boost/integral_stack.h"

namespace fusedet::boosting {

// Scan, AND chain, group, then the laser extent (laser_extent.h).
std::vector<Detection> detectChain(const std::vector<const Detector*>& chain, const LayerStack& stack,
                                   const DetectionSetup& setup, ScanStats* stats) {
  if (chain.empty()) throw std::invalid_argument("detectChain: no cascade given");
  const Detector& first = *chain.front();
  std::vector<RawHit> hits = first.scan(stack, setup.scan, stats);
  for (std::size_t k = 1; k < chain.size() && !hits.empty(); ++k) {
    const Cascade& c = chain[k]->cascade();
    if (c.isOpenCv()) throw std::invalid_argument(c.source + ": an OpenCV cascade cannot be AND-combined");
    const IntegralStack integrals = integrateFor(c, stack);
    std::vector<RawHit> kept;
    for (const RawHit& h : hits)
      if (evaluateWindow(c, integrals, h.box).accepted) kept.push_back(h);
    hits = std::move(kept);
  }
  std::vector<Detection> dets = groupHits(hits, setup.group, first.cascade().className, stack);
  refineToLaserExtent(dets, stack, setup.laserExtent);
  return dets;
}

EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const std::vector<std::size_t>& indices, const MatchConfig& match,
                          const DetectionSetup& setup) {
  EvalOutcome out;
  double totalMs = 0;
  for (std::size_t i : indices) {
    const DatasetItem& item = items.at(i);
    ScanStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<Detection> dets = detectChain(chain, item.stack, setup, &stats);
    totalMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    out.windows += stats.windows;
    out.stumps += stats.stumps;
    StackMatch m = matchDetections(dets, item.labels, match);
    out.counts.add(m);
    out.frames.push_back(frameOutcome(dets, m));
    out.detections.push_back(std::move(dets));
    out.matches.push_back(std::move(m));
  }
  out.msPerStack = indices.empty() ? 0.0 : totalMs / static_cast<double>(indices.size());
  return out;
}

EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const MatchConfig& match, const DetectionSetup& setup) {
  std::vector<std::size_t> all(items.size());
  std::iota(all.begin(), all.end(), 0);
  return evaluateChain(chain, items, all, match, setup);
}

}  // namespace fusedet::boosting
