// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/detector.h"

#include "fusedet/boost/integral_grids.h"
#include "fusedet/boost/parallel_for.h"
#include "opencv_pyramid.h"
#include "fusedet/boost/scalar_scan.h"
#include "fusedet/boost/window_scanner.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <tuple>


namespace fusedet::boosting {

namespace {

template <class Body>
void forEachRow(std::size_t rows, int threads, const Body& body) {
  if (threads == 1) {
    for (std::size_t i = 0; i < rows; ++i) body(i);
    return;
  }
  auto run = [&] {
    parallelFor(tbb::blocked_range<std::size_t>(0, rows), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) body(i);
    });
  };
  if (threads > 1) {
    tbb::task_arena arena(std::min(threads, tbb::info::default_concurrency()));
    arena.execute(run);
  } else {
    run();
  }
}

}  // namespace

WindowResult evaluateWindow(const Cascade& c, const IntegralStack& in, const Box& window) {
  if (c.isOpenCv())
    throw std::invalid_argument("evaluateWindow: OpenCV models run on their image pyramid (Detector::scan)");
  WindowResult r;
  for (const Stage& st : c.stages) {
    double sum = 0;
    for (const Stump& t : st.stumps) {
      const float v = featureValue(in, c.features[static_cast<std::size_t>(t.feature)], window);
      sum += v < static_cast<float>(t.threshold) ? t.left : t.right;
    }
    r.score = sum;
    if (sum < st.threshold) return r;
    ++r.stagesPassed;
  }
  r.accepted = true;
  return r;
}

IntegralStack integrateFor(const Cascade& c, const LayerStack& stack) {
  requireStackNetwork(c, stack);
  return IntegralStack(stack, c.layers, c.referenceHue);
}

Detector::Detector(Cascade cascade) : cascade_(std::move(cascade)) { cascade_.validate(); }
Detector::~Detector() = default;
Detector::Detector(Detector&&) noexcept = default;
Detector& Detector::operator=(Detector&&) noexcept = default;

std::vector<RawHit> Detector::scan(const LayerStack& stack, const ScanParams& params, ScanStats* stats) const {
  if (cascade_.isOpenCv()) return scanOpenCvPyramid(cascade_, stack, params, stats);
  const IntegralGrids grids(stack, layerRequests(cascade_), params.threads);
  std::vector<ScanStats> st;
  std::vector<std::vector<RawHit>> hits = scanCascades({&cascade_}, grids, params, stats ? &st : nullptr);
  if (stats) {
    stats->windows += st[0].windows;
    stats->stumps += st[0].stumps;
    stats->scales += st[0].scales;
  }
  return std::move(hits[0]);
}

std::vector<RawHit> Detector::scan(const IntegralStack& in, const ScanParams& params, ScanStats* stats) const {
  if (cascade_.isOpenCv())
    throw std::invalid_argument("Detector::scan: OpenCV models scan a LayerStack (their own pyramid)");
  if (in.size() != cascade_.layers.size())
    throw std::invalid_argument("Detector::scan: integrals hold " + std::to_string(in.size()) +
                                " layers, the model reads " + std::to_string(cascade_.layers.size()));
  const std::vector<ScalePlan> plans = planScales(cascade_, in, params);
  // Work items: a band of columns of one scale, all its rows. Bands keep the integral rows a
  // window touches in cache while y advances (a whole image row of 7 double layers does not fit);
  // all scales share one index space so that threads share the work across scales.
  constexpr std::size_t kBand = 48;  // window positions per band
  struct Item {
    std::size_t scale, x0, x1;
  };
  std::vector<Item> items;
  for (std::size_t s = 0; s < plans.size(); ++s)
    for (std::size_t x0 = 0; x0 < plans[s].xs.size(); x0 += kBand)
      items.push_back(Item{s, x0, std::min(plans[s].xs.size(), x0 + kBand)});
  std::vector<std::vector<RawHit>> hits(items.size());
  std::vector<std::size_t> stumpCount(items.size(), 0);
  const std::size_t nl = in.size();
  std::vector<const double*> layerData(nl);
  for (std::size_t l = 0; l < nl; ++l) layerData[l] = in.layer(l).sum.data();
  forEachRow(items.size(), params.threads, [&](std::size_t i) {
    const Item& it = items[i];
    const ScalePlan& sp = plans[it.scale];
    std::vector<const double*> base(nl), rowBase(nl);
    std::size_t stumps = 0;
    for (std::size_t yi = 0; yi < sp.ys.size(); ++yi) {
      for (std::size_t l = 0; l < nl; ++l) rowBase[l] = layerData[l] + sp.rowOfs[l][yi];
      for (std::size_t xi = it.x0; xi < it.x1; ++xi) {
        for (std::size_t l = 0; l < nl; ++l) base[l] = rowBase[l] + sp.colOfs[l][xi];
        const WindowResult r = runWindow(sp, base.data(), stumps);
        if (r.accepted)
          hits[i].push_back(RawHit{Box{double(sp.xs[xi]), double(sp.ys[yi]), double(sp.winW), double(sp.winH)},
                                   r.score, static_cast<int>(it.scale)});
      }
    }
    stumpCount[i] = stumps;
  });
  // (scale, row, column) order, whatever the bands and threads: each window occurs once.
  std::vector<RawHit> out;
  for (auto& h : hits) out.insert(out.end(), h.begin(), h.end());
  std::sort(out.begin(), out.end(), [](const RawHit& a, const RawHit& b) {
    return std::tie(a.scale, a.box.y, a.box.x) < std::tie(b.scale, b.box.y, b.box.x);
  });
  if (stats) {
    stats->scales += plans.size();
    for (const ScalePlan& sp : plans) stats->windows += sp.xs.size() * sp.ys.size();
    for (std::size_t n : stumpCount) stats->stumps += n;
  }
  return out;
}

}  // namespace fusedet::boosting
