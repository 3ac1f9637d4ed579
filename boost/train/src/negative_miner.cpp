// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/negative_miner.h"

#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <random>

#include "fusedet/boost/scalar_scan.h"
#include "fusedet/boost/parallel_for.h"
#include "fusedet/boost/window_scanner.h"

namespace fusedet::boosting {

namespace {

bool sameStage(const Cascade& a, const Cascade& b, std::size_t i) {
  const Stage &x = a.stages[i], &y = b.stages[i];
  if (x.threshold != y.threshold || x.stumps.size() != y.stumps.size()) return false;
  for (std::size_t k = 0; k < x.stumps.size(); ++k) {
    const Stump &s = x.stumps[k], &t = y.stumps[k];
    if (s.threshold != t.threshold || s.left != t.left || s.right != t.right) return false;
    if (!(a.features.at(static_cast<std::size_t>(s.feature)) == b.features.at(static_cast<std::size_t>(t.feature))))
      return false;
  }
  return true;
}

// Window k of a stack in scan order (scale, row, column), as Detector::scan reports it.
struct WindowIndex {
  std::size_t scale = 0, row = 0, column = 0;
};

class ScanOrder {
 public:
  explicit ScanOrder(const std::vector<ScaleWindows>& scales) : scales_(scales) {
    start_.push_back(0);
    for (const ScaleWindows& w : scales) start_.push_back(start_.back() + w.xs.size() * w.ys.size());
  }
  std::size_t size() const { return start_.back(); }
  // Fastest for increasing k (the cursor only moves forward then).
  WindowIndex at(std::size_t k) const {
    if (k < start_[cursor_]) cursor_ = 0;
    std::size_t& s = cursor_;
    while (k >= start_[s + 1]) ++s;
    const std::size_t local = k - start_[s], nx = scales_[s].xs.size();
    return WindowIndex{s, local / nx, local % nx};
  }
  Box box(std::size_t k) const {
    const WindowIndex w = at(k);
    const ScaleWindows& sw = scales_[w.scale];
    return Box{double(sw.xs[w.column]), double(sw.ys[w.row]), double(sw.winW), double(sw.winH)};
  }

 private:
  const std::vector<ScaleWindows>& scales_;
  std::vector<std::size_t> start_;
  mutable std::size_t cursor_ = 0;
};

template <class Body>
void forEachStack(std::size_t n, int threads, const Body& body) {
  if (threads == 1) {
    for (std::size_t s = 0; s < n; ++s) body(s);
    return;
  }
  tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
  arena.execute([&] {
    parallelFor(tbb::blocked_range<std::size_t>(0, n, 1), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t s = r.begin(); s != r.end(); ++s) body(s);
    });
  });
}

}  // namespace

NegativeMiner::NegativeMiner(const TrainingStacks& stacks) : stacks_(stacks) {}
NegativeMiner::~NegativeMiner() = default;

bool NegativeMiner::extends(const Cascade& c) const {
  if (!started_ || c.windowWidth != applied_.windowWidth || c.windowHeight != applied_.windowHeight ||
      c.layers != applied_.layers || c.referenceHue != applied_.referenceHue ||
      c.stages.size() < applied_.stages.size())
    return false;
  for (std::size_t i = 0; i < applied_.stages.size(); ++i)
    if (!sameStage(applied_, c, i)) return false;
  return true;
}

void NegativeMiner::update(const Cascade& cascade, int threads) {
  const std::size_t n = stacks_.originalStacks();
  const ScanParams& params = stacks_.config().scan;
  auto mine = [&](std::size_t s) { return stacks_.owner(s) == stacks_.shard().rank; };
  if (!extends(cascade)) {
    // Every label-free window: what the first harvest (no stage yet) takes as candidates.
    applied_ = cascade;
    applied_.stages.clear();
    alive_.assign(n, {});
    windows_.assign(n, 0);
    scales_.assign(n, {});
    forEachStack(n, threads, [&](std::size_t s) {
      if (!mine(s)) return;
      const IntegralStack& in = stacks_.integrals(s);
      scales_[s] = windowScales(applied_, in.width(), in.height(), params);
      const ScanOrder order(scales_[s]);
      windows_[s] = order.size();
      const NegativeWindowTest labelFree(stacks_.labels(s), stacks_.config());
      std::vector<std::uint32_t>& alive = alive_[s];
      std::size_t k = 0;
      for (const ScaleWindows& w : scales_[s])
        for (int y : w.ys)
          for (int x : w.xs) {
            if (labelFree(Box{double(x), double(y), double(w.winW), double(w.winH)}))
              alive.push_back(static_cast<std::uint32_t>(k));
            ++k;
          }
    });
    started_ = true;
  }
  if (cascade.stages.size() == applied_.stages.size()) return;
  // Only the stages not applied yet, on the windows every earlier stage accepted.
  Cascade fresh = cascade;
  fresh.stages.erase(fresh.stages.begin(), fresh.stages.begin() + static_cast<std::ptrdiff_t>(applied_.stages.size()));
  forEachStack(n, threads, [&](std::size_t s) {
    if (!mine(s)) return;
    const IntegralStack& in = stacks_.integrals(s);
    const std::vector<ScalePlan> plans = planScales(fresh, in, params);
    const ScanOrder order(scales_[s]);
    const std::size_t nl = in.size();
    std::vector<const double*> layerData(nl), base(nl);
    for (std::size_t l = 0; l < nl; ++l) layerData[l] = in.layer(l).sum.data();
    std::size_t stumps = 0;
    std::vector<std::uint32_t>& alive = alive_[s];
    std::size_t kept = 0;
    for (const std::uint32_t k : alive) {
      const WindowIndex w = order.at(k);
      const ScalePlan& sp = plans[w.scale];
      for (std::size_t l = 0; l < nl; ++l) base[l] = layerData[l] + sp.rowOfs[l][w.row] + sp.colOfs[l][w.column];
      if (runWindow(sp, base.data(), stumps).accepted) alive[kept++] = k;
    }
    alive.resize(kept);
  });
  applied_.features = cascade.features;
  applied_.stages = cascade.stages;
}

NegativeHarvest NegativeMiner::harvest(const Cascade& cascade, std::size_t wanted, std::uint64_t seed,
                                       int threads) {
  update(cascade, threads);
  NegativeHarvest h;
  std::mt19937_64 rng(seed);
  for (std::size_t s = 0; s < alive_.size(); ++s) {
    h.windowsScanned += windows_[s];
    const ScanOrder order(scales_[s]);
    for (const std::uint32_t k : alive_[s]) {
      // The draws of harvestNegatives(), candidate by candidate.
      const std::size_t c = h.candidates++;
      if (c < wanted) {
        h.samples.push_back(Sample{static_cast<std::uint32_t>(s), order.box(k)});
      } else {
        const std::uint64_t j = rng() % (c + 1);
        if (j < wanted) h.samples[j] = Sample{static_cast<std::uint32_t>(s), order.box(k)};
      }
    }
  }
  return h;
}

std::vector<Box> NegativeMiner::candidateWindows(std::size_t s) const {
  const ScanOrder order(scales_.at(s));
  std::vector<Box> out;
  out.reserve(alive_[s].size());
  for (const std::uint32_t k : alive_[s]) out.push_back(order.box(k));
  return out;
}

}  // namespace fusedet::boosting
