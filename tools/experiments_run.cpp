#include "experiments_run.h"

#include <chrono>
#include <stdexcept>

#include "fusedet/boost/integral_stack.h"

namespace fusedet::tools::experiments {

std::vector<Detection> detectChain(const std::vector<const boosting::Detector*>& chain,
                                   const LayerStack& stack, const DetectionSetup& setup,
                                   boosting::ScanStats* stats) {
  if (chain.empty()) throw std::invalid_argument("detectChain: no cascade given");
  const boosting::Detector& first = *chain.front();
  if (chain.size() == 1) {
    const std::vector<boosting::RawHit> hits = first.scan(stack, setup.scan, stats);
    return boosting::groupHits(hits, setup.group, first.cascade().className, stack);
  }
  std::vector<boosting::RawHit> hits = first.scan(stack, setup.scan, stats);
  for (std::size_t k = 1; k < chain.size() && !hits.empty(); ++k) {
    const boosting::Cascade& c = chain[k]->cascade();
    if (c.isOpenCv()) throw std::invalid_argument(c.source + ": an OpenCV cascade cannot be AND-combined");
    const boosting::IntegralStack integrals = boosting::integrateFor(c, stack);
    std::vector<boosting::RawHit> kept;
    for (const boosting::RawHit& h : hits)
      if (boosting::evaluateWindow(c, integrals, h.box).accepted) kept.push_back(h);
    hits = std::move(kept);
  }
  return boosting::groupHits(hits, setup.group, first.cascade().className, stack);
}

EvalOutcome evaluateChain(const std::vector<const boosting::Detector*>& chain,
                          const std::vector<DatasetItem>& items, const boosting::MatchConfig& match,
                          const DetectionSetup& setup) {
  EvalOutcome out;
  double totalMs = 0;
  for (const DatasetItem& item : items) {
    boosting::ScanStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<Detection> dets = detectChain(chain, item.stack, setup, &stats);
    totalMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    out.windows += stats.windows;
    out.stumps += stats.stumps;
    boosting::StackMatch m = boosting::matchDetections(dets, item.labels, match);
    out.counts.add(m);
    out.detections.push_back(std::move(dets));
    out.matches.push_back(std::move(m));
  }
  out.msPerStack = items.empty() ? 0.0 : totalMs / static_cast<double>(items.size());
  return out;
}

}  // namespace fusedet::tools::experiments
