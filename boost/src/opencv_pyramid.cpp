#include "opencv_pyramid.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::boosting {

namespace {

// cvRound: nearest, ties to even (lrint in the default rounding mode).
inline int cvRoundF(float v) { return static_cast<int>(std::lrintf(v)); }
inline int cvRoundD(double v) { return static_cast<int>(std::lrint(v)); }

// A stump with its rectangles as offsets from the window's top-left corner in the integral
// buffer (sum and tilted share one buffer, tilted behind sum): OpenCV's OptFeature, flattened.
struct CvStump {
  std::array<std::array<std::int32_t, 4>, 3> ofs{};
  std::array<float, 3> weight{};
  int count = 2;
  float threshold = 0;
  float left = 0, right = 0;
};

struct CvStage {
  std::uint32_t begin = 0, end = 0;
  float threshold = 0;
};

struct CvModel {
  int winW = 0, winH = 0;
  std::vector<CvStump> stumps;
  std::vector<CvStage> stages;
  bool tilted = false;
  std::array<std::int32_t, 4> norm{};  // normrect corners (1, 1, w-2, h-2)
  double normArea = 0;
};

CvModel compile(const Cascade& c, std::ptrdiff_t stride, std::ptrdiff_t tiltedOffset) {
  CvModel m;
  m.winW = c.windowWidth;
  m.winH = c.windowHeight;
  for (const HaarFeature& f : c.haarFeatures) m.tilted = m.tilted || f.tilted;
  auto at = [stride](int x, int y) { return static_cast<std::int32_t>(y * stride + x); };
  m.norm = {at(1, 1), at(m.winW - 1, 1), at(1, m.winH - 1), at(m.winW - 1, m.winH - 1)};
  m.normArea = double(m.winW - 2) * double(m.winH - 2);
  for (const Stage& st : c.stages) {
    CvStage cs;
    cs.begin = static_cast<std::uint32_t>(m.stumps.size());
    cs.threshold = static_cast<float>(st.threshold);
    for (const Stump& t : st.stumps) {
      const HaarFeature& f = c.haarFeatures[static_cast<std::size_t>(t.feature)];
      CvStump z;
      z.count = f.count;
      for (int i = 0; i < f.count; ++i) {
        const HaarRect& r = f.rects[static_cast<std::size_t>(i)];
        auto& o = z.ofs[static_cast<std::size_t>(i)];
        if (!f.tilted) {
          o = {at(r.x, r.y), at(r.x + r.w, r.y), at(r.x, r.y + r.h), at(r.x + r.w, r.y + r.h)};
        } else {
          const auto t0 = static_cast<std::int32_t>(tiltedOffset);
          o = {t0 + at(r.x, r.y), t0 + at(r.x - r.h, r.y + r.h), t0 + at(r.x + r.w, r.y + r.w),
               t0 + at(r.x + r.w - r.h, r.y + r.w + r.h)};
        }
        z.weight[static_cast<std::size_t>(i)] = r.weight;
      }
      z.threshold = static_cast<float>(t.threshold);
      z.left = static_cast<float>(t.left);
      z.right = static_cast<float>(t.right);
      m.stumps.push_back(z);
    }
    cs.end = static_cast<std::uint32_t>(m.stumps.size());
    m.stages.push_back(cs);
  }
  return m;
}

inline int rectSum(const std::int32_t* p, const std::array<std::int32_t, 4>& o) {
  // Wrapping arithmetic like OpenCV's int sums (done unsigned: defined behaviour).
  return static_cast<int>(static_cast<std::uint32_t>(p[o[0]]) - static_cast<std::uint32_t>(p[o[1]]) -
                          static_cast<std::uint32_t>(p[o[2]]) + static_cast<std::uint32_t>(p[o[3]]));
}

// OpenCV's runAt: -1 = window not evaluated (flat), -k = rejected by stage k (0 = first), 1 = accepted.
inline int runAt(const CvModel& m, const std::int32_t* p, const std::uint32_t* q, double& score,
                 std::size_t& stumps) {
  const int valsum = rectSum(p, m.norm);
  const std::uint32_t valsqsum = q[m.norm[0]] - q[m.norm[1]] - q[m.norm[2]] + q[m.norm[3]];
  double nf = m.normArea * double(valsqsum) - double(valsum) * double(valsum);
  if (!(nf > 0.)) return -1;
  nf = std::sqrt(nf);
  const auto vnf = static_cast<float>(1. / nf);
  if (!(m.normArea * vnf < 1e-1)) return -1;
  const CvStump* z = m.stumps.data();
  const int nStages = static_cast<int>(m.stages.size());
  for (int s = 0; s < nStages; ++s) {
    const CvStage& st = m.stages[static_cast<std::size_t>(s)];
    double sum = 0;
    for (std::uint32_t k = st.begin; k < st.end; ++k) {
      const CvStump& t = z[k];
      float v = t.weight[0] * static_cast<float>(rectSum(p, t.ofs[0])) +
                t.weight[1] * static_cast<float>(rectSum(p, t.ofs[1]));
      if (t.count == 3) v += t.weight[2] * static_cast<float>(rectSum(p, t.ofs[2]));
      v *= vnf;
      sum += v < t.threshold ? t.left : t.right;
    }
    stumps += st.end - st.begin;
    score = sum;
    if (sum < st.threshold) return -s;
  }
  return 1;
}

cv::Mat eightBit(const Layer& l) {
  if (l.data.depth() == CV_8U) return l.data;
  cv::Mat out;
  l.data.convertTo(out, CV_8U);  // values taken as grey levels 0..255, saturated
  return out;
}

}  // namespace

void integrateCv(const cv::Mat& gray, bool tilted, CvIntegrals& out) {
  const int w = gray.cols, h = gray.rows;
  out.width = w;
  out.height = h;
  const std::ptrdiff_t s = w + 1;
  const std::size_t n = static_cast<std::size_t>(s) * static_cast<std::size_t>(h + 1);
  out.sum.assign(n, 0);
  out.sqsum.assign(n, 0);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = gray.ptr<std::uint8_t>(y);
    const std::int32_t* prev = out.sum.data() + y * s;
    std::int32_t* cur = out.sum.data() + (y + 1) * s;
    const std::uint32_t* qprev = out.sqsum.data() + y * s;
    std::uint32_t* qcur = out.sqsum.data() + (y + 1) * s;
    std::int32_t rs = 0;
    std::uint32_t rq = 0;
    for (int x = 0; x < w; ++x) {
      const std::uint32_t v = row[x];
      rs += static_cast<std::int32_t>(v);
      rq += v * v;
      cur[x + 1] = prev[x + 1] + rs;
      qcur[x + 1] = qprev[x + 1] + rq;
    }
  }
  out.tilted.clear();
  if (!tilted) return;
  // T(X, Y) = sum of pixels (x, y) with y < Y and |x - X + 1| <= Y - 1 - y (a triangle with its apex
  // at pixel (X - 1, Y - 1)). Recurrence: T(X, Y) = T(X-1, Y-1) + T(X+1, Y-1) - T(X, Y-2)
  // + I(X-1, Y-1) + I(X-1, Y-2), run on columns padded by h + 2 on both sides (zero pixels) so the
  // triangles never reach an unpadded edge, then cropped to [0, w].
  const int pad = h + 2;
  const int pw = w + 1 + 2 * pad;
  std::vector<std::int32_t> t(static_cast<std::size_t>(pw) * static_cast<std::size_t>(h + 1), 0);
  auto T = [&](int X, int Y) -> std::int32_t& { return t[static_cast<std::size_t>(Y) * pw + (X + pad)]; };
  auto I = [&](int x, int y) -> std::int32_t {
    return (x >= 0 && x < w && y >= 0 && y < h) ? gray.ptr<std::uint8_t>(y)[x] : 0;
  };
  for (int Y = 1; Y <= h; ++Y)
    for (int X = -pad + 1; X < w + 1 + pad - 1; ++X) {
      std::int32_t v = T(X - 1, Y - 1) + T(X + 1, Y - 1) + I(X - 1, Y - 1);
      if (Y >= 2) v += I(X - 1, Y - 2) - T(X, Y - 2);
      T(X, Y) = v;
    }
  out.tilted.assign(n, 0);
  for (int Y = 0; Y <= h; ++Y)
    for (int X = 0; X <= w; ++X) out.tilted[static_cast<std::size_t>(Y * s + X)] = T(X, Y);
}

std::vector<RawHit> scanOpenCvPyramid(const Cascade& c, const LayerStack& stack, const ScanParams& params,
                                      ScanStats* stats) {
  if (!(params.scaleFactor > 1)) throw std::invalid_argument("scale factor must be > 1");
  const Layer& layer = stack.at(c.layers.at(0));
  const cv::Mat img = eightBit(layer);
  const cv::Size imgsz = img.size();
  const double toRefX = stack.width() > 0 ? double(stack.width()) / imgsz.width : 1.0;
  const double toRefY = stack.height() > 0 ? double(stack.height()) / imgsz.height : 1.0;
  const int maxW = params.maxWidth > 0 ? params.maxWidth : imgsz.width;
  const int maxH = params.maxHeight > 0 ? params.maxHeight : imgsz.height;
  std::vector<float> scales;
  for (double factor = 1;; factor *= params.scaleFactor) {
    const int ww = cvRoundD(c.windowWidth * factor), wh = cvRoundD(c.windowHeight * factor);
    if (ww > maxW || wh > maxH || ww > imgsz.width || wh > imgsz.height) break;
    if (ww < params.minWidth || wh < params.minHeight) continue;
    scales.push_back(static_cast<float>(factor));
  }
  std::vector<RawHit> out;
  bool tilted = false;
  for (const HaarFeature& f : c.haarFeatures) tilted = tilted || f.tilted;
  CvIntegrals in;
  cv::Mat resized;
  for (std::size_t si = 0; si < scales.size(); ++si) {
    const float sc = scales[si];
    const cv::Size sz(cvRoundF(float(imgsz.width) / sc), cvRoundF(float(imgsz.height) / sc));
    if (sz == imgsz) resized = img;
    else cv::resize(img, resized, sz, 1. / sc, 1. / sc, cv::INTER_LINEAR_EXACT);
    integrateCv(resized, tilted, in);
    const std::ptrdiff_t stride = in.stride();
    // One buffer: sum, then tilted (offsets of tilted rectangles include the distance).
    std::vector<std::int32_t> buf;
    const std::int32_t* sumBase = in.sum.data();
    std::ptrdiff_t tiltedOffset = 0;
    if (tilted) {
      buf.reserve(in.sum.size() * 2);
      buf.insert(buf.end(), in.sum.begin(), in.sum.end());
      buf.insert(buf.end(), in.tilted.begin(), in.tilted.end());
      sumBase = buf.data();
      tiltedOffset = static_cast<std::ptrdiff_t>(in.sum.size());
    }
    const CvModel m = compile(c, stride, tiltedOffset);
    const int ystep = sc >= 2 ? 1 : 2;
    const int szwW = std::max(sz.width + 1 - m.winW, 0), szwH = std::max(sz.height + 1 - m.winH, 0);
    const int winW = cvRoundF(float(m.winW) * sc), winH = cvRoundF(float(m.winH) * sc);
    const int rows = (szwH + ystep - 1) / ystep;
    std::vector<std::vector<RawHit>> hits(static_cast<std::size_t>(rows));
    std::vector<std::size_t> windows(static_cast<std::size_t>(rows), 0), stumps(static_cast<std::size_t>(rows), 0);
    auto row = [&](int ri) {
      const int y = ri * ystep;
      std::size_t nw = 0, ns = 0;
      auto& h = hits[static_cast<std::size_t>(ri)];
      for (int x = 0; x < szwW; x += ystep) {
        const std::ptrdiff_t o = y * stride + x;
        double score = 0;
        ++nw;
        const int r = runAt(m, sumBase + o, in.sqsum.data() + o, score, ns);
        if (r > 0)
          h.push_back(RawHit{Box{cvRoundF(float(x) * sc) * toRefX, cvRoundF(float(y) * sc) * toRefY, winW * toRefX,
                                 winH * toRefY},
                             score, static_cast<int>(si)});
        if (r == 0) x += ystep;
      }
      windows[static_cast<std::size_t>(ri)] = nw;
      stumps[static_cast<std::size_t>(ri)] = ns;
    };
    if (params.threads == 1) {
      for (int ri = 0; ri < rows; ++ri) row(ri);
    } else {
      auto run = [&] {
        tbb::parallel_for(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& r) {
          for (int ri = r.begin(); ri != r.end(); ++ri) row(ri);
        });
      };
      if (params.threads > 1) {
        tbb::task_arena arena(params.threads);
        arena.execute(run);
      } else {
        run();
      }
    }
    for (auto& h : hits) out.insert(out.end(), h.begin(), h.end());
    if (stats) {
      for (std::size_t n : windows) stats->windows += n;
      for (std::size_t n : stumps) stats->stumps += n;
    }
  }
  if (stats) stats->scales += scales.size();
  return out;
}

}  // namespace fusedet::boosting
