// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/scalar_scan.h"

#include <algorithm>
#include <cmath>

#include "fusedet/boost/window_scanner.h"

namespace fusedet::boosting {

namespace {

int roundHalfUp(double v) { return static_cast<int>(std::floor(v + 0.5)); }

}  // namespace

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

}  // namespace fusedet::boosting
