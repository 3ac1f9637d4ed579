#include "fusedet/boost/detector.h"

#include "integral_grids.h"
#include "opencv_pyramid.h"
#include "window_scanner.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <stdexcept>
#include <tuple>


namespace fusedet::boosting {

namespace {

int roundHalfUp(double v) { return static_cast<int>(std::floor(v + 0.5)); }

// One stump with its feature laid out for one scale: rectangle corners as offsets from the
// window's origin in its layer's integral (OpenCV's OptFeature idea), flat for the hot loop.
// Branch-free form of FeatureLayout (stump types mix unpredictably): black = rect 0 + rect 1
// (rect 1 is an empty rectangle, sum exactly 0, unless the type has two black parts), white =
// rect 2 - rest * black with rest = 1 when rect 2 is the outer rectangle, else 0. Same values as
// featureValue() (adding or subtracting an exact zero changes nothing but the sign of a zero).
struct ScaledStump {
  int layer = 0;
  std::array<std::array<std::int32_t, 4>, 3> ofs{};  // (x0,y0) (x1,y0) (x0,y1) (x1,y1)
  double rest = 0;
  double blackArea = 1, whiteArea = 1;
  float threshold = 0;
  std::array<double, 2> leaf{};  // left, right: indexed, not branched on
};

struct ScaledStage {
  std::size_t begin = 0, end = 0;  // range in the stump array
  double threshold = 0;
};

struct ScalePlan {
  int winW = 0, winH = 0, step = 1;
  std::vector<int> xs, ys;                       // window positions (reference pixels)
  std::vector<std::vector<std::ptrdiff_t>> colOfs, rowOfs;  // per layer, per position
  std::vector<ScaledStump> stumps;
  std::vector<ScaledStage> stages;
};

std::vector<ScalePlan> planScales(const Cascade& c, const IntegralStack& in, const ScanParams& p) {
  const int W = in.width(), H = in.height();
  std::vector<ScalePlan> plans;
  for (ScaleWindows& win : windowScales(c, W, H, p)) {
    ScalePlan sp;
    sp.winW = win.winW;
    sp.winH = win.winH;
    sp.step = win.step;
    sp.xs = std::move(win.xs);
    sp.ys = std::move(win.ys);
    const std::size_t nl = in.size();
    sp.colOfs.resize(nl);
    sp.rowOfs.resize(nl);
    std::vector<std::array<int, 2>> lwSize(nl);
    for (std::size_t l = 0; l < nl; ++l) {
      const LayerIntegral& li = in.layer(l);
      lwSize[l] = layerWindowSize(li, W, H, sp.winW, sp.winH);
      const double sx = double(li.width) / W, sy = double(li.height) / H;
      for (int x : sp.xs) sp.colOfs[l].push_back(std::clamp(roundHalfUp(x * sx), 0, li.width - lwSize[l][0]));
      for (int y : sp.ys)
        sp.rowOfs[l].push_back(std::ptrdiff_t(std::clamp(roundHalfUp(y * sy), 0, li.height - lwSize[l][1])) *
                               li.stride());
    }
    for (const Stage& st : c.stages) {
      ScaledStage ss{sp.stumps.size(), 0, st.threshold};
      for (const Stump& t : st.stumps) {
        const Feature& f = c.features[static_cast<std::size_t>(t.feature)];
        const auto l = static_cast<std::size_t>(f.layer);
        const std::ptrdiff_t stride = in.layer(l).stride();
        const FeatureLayout lay = layoutFeature(f.type, featureRectInWindow(f, lwSize[l][0], lwSize[l][1]));
        ScaledStump z;
        z.layer = f.layer;
        z.rest = lay.whiteIsRest ? 1.0 : 0.0;
        z.blackArea = lay.blackArea;
        z.whiteArea = lay.whiteArea;
        auto corners = [stride](const PixelRect& r) {
          return std::array<std::int32_t, 4>{
              static_cast<std::int32_t>(r.y0 * stride + r.x0), static_cast<std::int32_t>(r.y0 * stride + r.x1),
              static_cast<std::int32_t>(r.y1 * stride + r.x0), static_cast<std::int32_t>(r.y1 * stride + r.x1)};
        };
        z.ofs[0] = corners(lay.rects[0]);
        z.ofs[1] = lay.blackCount == 2 ? corners(lay.rects[1]) : std::array<std::int32_t, 4>{0, 0, 0, 0};
        z.ofs[2] = corners(lay.rects[static_cast<std::size_t>(lay.blackCount)]);
        z.threshold = static_cast<float>(t.threshold);
        z.leaf = {t.left, t.right};
        sp.stumps.push_back(z);
      }
      ss.end = sp.stumps.size();
      sp.stages.push_back(ss);
    }
    plans.push_back(std::move(sp));
  }
  return plans;
}

// The hot loop: same arithmetic, in the same order, as featureValue() + evaluateWindow().
inline WindowResult runWindow(const ScalePlan& sp, const double* const* base, std::size_t& stumps) {
  WindowResult r;
  for (const ScaledStage& st : sp.stages) {
    double sum = 0;
    for (std::size_t k = st.begin; k < st.end; ++k) {
      const ScaledStump& z = sp.stumps[k];
      const double* p = base[z.layer];
      auto rs = [p](const std::array<std::int32_t, 4>& o) { return p[o[3]] - p[o[1]] - p[o[2]] + p[o[0]]; };
      const double black = rs(z.ofs[0]) + rs(z.ofs[1]);
      const double white = rs(z.ofs[2]) - z.rest * black;
      const auto v = static_cast<float>(black / z.blackArea - white / z.whiteArea);
      sum += z.leaf[static_cast<std::size_t>(!(v < z.threshold))];
    }
    stumps += st.end - st.begin;
    r.score = sum;
    if (sum < st.threshold) return r;
    ++r.stagesPassed;
  }
  r.accepted = true;
  return r;
}

template <class Body>
void forEachRow(std::size_t rows, int threads, const Body& body) {
  if (threads == 1) {
    for (std::size_t i = 0; i < rows; ++i) body(i);
    return;
  }
  auto run = [&] {
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows), [&](const tbb::blocked_range<std::size_t>& r) {
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
  return IntegralStack(stack, c.layers, c.referenceHue, false);
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
