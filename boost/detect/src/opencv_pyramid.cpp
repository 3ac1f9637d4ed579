// SPDX-License-Identifier: Apache-2.0
#include "opencv_pyramid.h"

#include "fusedet/boost/vector_path.h"

#include "fusedet/boost/opencv_cascade.h"
#include "fusedet/boost/parallel_for.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

#if defined(__x86_64__) && defined(__GNUC__)
#include <immintrin.h>
#endif

namespace fusedet::boosting {

namespace {

constexpr std::size_t kReadPad = 64;

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
  std::uint32_t begin = 0, end = 0;  // stumps, or trees for a tree cascade
  float threshold = 0;
};

// Tree cascades: nodes carry a feature each; children > 0 are node offsets, <= 0 leaves.
struct CvNode {
  std::array<std::array<std::int32_t, 4>, 3> ofs{};
  std::array<float, 3> weight{};
  int count = 2;
  float threshold = 0;
  int left = 0, right = 0;
};
struct CvTree {
  std::uint32_t node = 0, leaf = 0;  // first node, first leaf
};

struct CvModel {
  int winW = 0, winH = 0;
  std::vector<CvStump> stumps;
  std::vector<CvStage> stages;
  bool tilted = false;
  bool trees = false;
  std::vector<CvNode> nodes;
  std::vector<CvTree> treeList;
  std::vector<float> leaves;
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
  // Rectangles of one feature as offsets (upright or tilted) and weights.
  auto layout = [&](const HaarFeature& f, std::array<std::array<std::int32_t, 4>, 3>& ofs, std::array<float, 3>& w) {
    for (int i = 0; i < f.count; ++i) {
      const HaarRect& r = f.rects[static_cast<std::size_t>(i)];
      auto& o = ofs[static_cast<std::size_t>(i)];
      if (!f.tilted) {
        o = {at(r.x, r.y), at(r.x + r.w, r.y), at(r.x, r.y + r.h), at(r.x + r.w, r.y + r.h)};
      } else {
        const auto t0 = static_cast<std::int32_t>(tiltedOffset);
        o = {t0 + at(r.x, r.y), t0 + at(r.x - r.h, r.y + r.h), t0 + at(r.x + r.w, r.y + r.w),
             t0 + at(r.x + r.w - r.h, r.y + r.w + r.h)};
      }
      w[static_cast<std::size_t>(i)] = r.weight;
    }
  };
  m.trees = c.hasTrees();
  for (std::size_t si = 0; si < c.stages.size(); ++si) {
    const Stage& st = c.stages[si];
    CvStage cs;
    cs.threshold = static_cast<float>(st.threshold);
    if (m.trees) {
      cs.begin = static_cast<std::uint32_t>(m.treeList.size());
      for (const Tree& t : c.treeStages[si]) {
        m.treeList.push_back(CvTree{static_cast<std::uint32_t>(m.nodes.size()), static_cast<std::uint32_t>(m.leaves.size())});
        for (const TreeNode& n : t.nodes) {
          const HaarFeature& f = c.haarFeatures[static_cast<std::size_t>(n.feature)];
          CvNode z;
          z.count = f.count;
          layout(f, z.ofs, z.weight);
          z.threshold = static_cast<float>(n.threshold);
          z.left = n.left;
          z.right = n.right;
          m.nodes.push_back(z);
        }
        for (double v : t.leaves) m.leaves.push_back(static_cast<float>(v));
      }
      cs.end = static_cast<std::uint32_t>(m.treeList.size());
      m.stages.push_back(cs);
      continue;
    }
    cs.begin = static_cast<std::uint32_t>(m.stumps.size());
    for (const Stump& t : st.stumps) {
      const HaarFeature& f = c.haarFeatures[static_cast<std::size_t>(t.feature)];
      CvStump z;
      z.count = f.count;
      layout(f, z.ofs, z.weight);
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

// OpenCV's setWindow: the variance normalisation factor, or false for a flat window (standard
// deviation over the inner area at most 10 grey levels, or zero).
inline bool normFactor(const CvModel& m, const std::int32_t* p, const std::uint32_t* q, float& vnf) {
  const int valsum = rectSum(p, m.norm);
  const std::uint32_t valsqsum = q[m.norm[0]] - q[m.norm[1]] - q[m.norm[2]] + q[m.norm[3]];
  double nf = m.normArea * double(valsqsum) - double(valsum) * double(valsum);
  if (!(nf > 0.)) return false;
  nf = std::sqrt(nf);
  vnf = static_cast<float>(1. / nf);
  return m.normArea * vnf < 1e-1;
}

// Tree cascades (OpenCV's predictOrdered): walk each tree from its root to a leaf.
int runTrees(const CvModel& m, const std::int32_t* p, float vnf, int first, double& score, std::size_t& weak) {
  const int nStages = static_cast<int>(m.stages.size());
  for (int s = first; s < nStages; ++s) {
    const CvStage& st = m.stages[static_cast<std::size_t>(s)];
    double sum = 0;
    for (std::uint32_t k = st.begin; k < st.end; ++k) {
      const CvTree& t = m.treeList[k];
      int idx = 0;
      do {
        const CvNode& n = m.nodes[t.node + static_cast<std::uint32_t>(idx)];
        float v = n.weight[0] * static_cast<float>(rectSum(p, n.ofs[0])) +
                  n.weight[1] * static_cast<float>(rectSum(p, n.ofs[1]));
        if (n.count == 3) v += n.weight[2] * static_cast<float>(rectSum(p, n.ofs[2]));
        v *= vnf;
        idx = v < n.threshold ? n.left : n.right;
      } while (idx > 0);
      sum += m.leaves[t.leaf + static_cast<std::uint32_t>(-idx)];
    }
    weak += st.end - st.begin;
    score = sum;
    if (sum < st.threshold) return -s;
  }
  return 1;
}

// Stages [first, end) of one window: -k = rejected by stage k, 1 = accepted (score = last sum).
inline int runFrom(const CvModel& m, const std::int32_t* p, float vnf, int first, double& score,
                   std::size_t& stumps) {
  if (m.trees) return runTrees(m, p, vnf, first, score, stumps);
  const CvStump* z = m.stumps.data();
  const int nStages = static_cast<int>(m.stages.size());
  for (int s = first; s < nStages; ++s) {
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

// OpenCV's runAt: -1 = flat window (not classified), -k = rejected by stage k, 1 = accepted.
inline int runAt(const CvModel& m, const std::int32_t* p, const std::uint32_t* q, double& score,
                 std::size_t& stumps) {
  float vnf = 1.f;
  if (!normFactor(m, p, q, vnf)) return -1;
  return runFrom(m, p, vnf, 0, score, stumps);
}

// One row of windows of one scale, given as the first window's pointers.
struct RowJob {
  const CvModel* m = nullptr;
  const std::int32_t* sum = nullptr;   // sum (and tilted) at the row's first window
  const std::uint32_t* sq = nullptr;   // squared sum at the row's first window
  int positions = 0;                   // windows in the row (x = 0, step, 2 step, ...)
  int step = 2;
};

struct RowResult {
  std::vector<std::pair<int, double>> hits;  // (position index, score)
  std::size_t windows = 0, stumps = 0;
};

// Reference path: OpenCV's loop verbatim, one window at a time.
void scanRowScalar(const RowJob& j, RowResult& out) {
  for (int i = 0; i < j.positions; ++i) {
    const std::ptrdiff_t o = std::ptrdiff_t(i) * j.step;
    double score = 0;
    ++out.windows;
    const int r = runAt(*j.m, j.sum + o, j.sq + o, score, out.stumps);
    if (r > 0) out.hits.emplace_back(i, score);
    if (r == 0) ++i;  // OpenCV skips the next position after a first-stage rejection
  }
}

#if defined(__x86_64__) && defined(__GNUC__)
#define FUSEDET_HAVE_AVX2_PATH 1

// Eight windows at once (positions i0 .. i0 + 7 of a row): vector loads of eight integral values
// at stride `kStep`, the same float and double operations per lane as runFrom(), lane by lane
// IEEE-identical (separate multiply and add, no FMA). OpenCV's skip rule is applied afterwards on
// the per-lane first-stage results, so the windows reported are exactly OpenCV's.
template <int kStep>
__attribute__((target("avx2"))) inline __m256i load8(const std::int32_t* p) {
  if constexpr (kStep == 1) {
    return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p));
  } else {
    const __m256i even = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
    const __m256i a = _mm256_permutevar8x32_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)), even);
    const __m256i b = _mm256_permutevar8x32_epi32(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(p + 8)), even);
    return _mm256_permute2x128_si256(a, b, 0x20);
  }
}

template <int kStep>
__attribute__((target("avx2"))) inline __m256i rectSum8(const std::int32_t* p, const std::array<std::int32_t, 4>& o) {
  return _mm256_sub_epi32(_mm256_sub_epi32(_mm256_add_epi32(load8<kStep>(p + o[0]), load8<kStep>(p + o[3])),
                                           load8<kStep>(p + o[1])),
                          load8<kStep>(p + o[2]));
}

// Sums of one stage for eight windows (lanes 0-3 in lo, 4-7 in hi).
template <int kStep>
__attribute__((target("avx2"))) inline void stage8(const CvModel& m, const CvStage& st, const std::int32_t* p,
                                                   __m256 vnf, __m256d& lo, __m256d& hi) {
  lo = _mm256_setzero_pd();
  hi = _mm256_setzero_pd();
  for (std::uint32_t k = st.begin; k < st.end; ++k) {
    const CvStump& t = m.stumps[k];
    __m256 v = _mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(t.weight[0]), _mm256_cvtepi32_ps(rectSum8<kStep>(p, t.ofs[0]))),
                             _mm256_mul_ps(_mm256_set1_ps(t.weight[1]), _mm256_cvtepi32_ps(rectSum8<kStep>(p, t.ofs[1]))));
    if (t.count == 3)
      v = _mm256_add_ps(v, _mm256_mul_ps(_mm256_set1_ps(t.weight[2]), _mm256_cvtepi32_ps(rectSum8<kStep>(p, t.ofs[2]))));
    v = _mm256_mul_ps(v, vnf);
    const __m256 lt = _mm256_cmp_ps(v, _mm256_set1_ps(t.threshold), _CMP_LT_OQ);
    const __m256 leaf = _mm256_blendv_ps(_mm256_set1_ps(t.right), _mm256_set1_ps(t.left), lt);
    lo = _mm256_add_pd(lo, _mm256_cvtps_pd(_mm256_castps256_ps128(leaf)));
    hi = _mm256_add_pd(hi, _mm256_cvtps_pd(_mm256_extractf128_ps(leaf, 1)));
  }
}

// setWindow for four windows: normalisation factors and the "not flat" mask.
__attribute__((target("avx2"))) inline __m128 norm4(__m128i s, __m128i q, __m256d area, int& okMask) {
  const __m256d sd = _mm256_cvtepi32_pd(s);
  const __m256d qd = _mm256_add_pd(_mm256_cvtepi32_pd(_mm_xor_si128(q, _mm_set1_epi32(INT32_MIN))),
                                   _mm256_set1_pd(2147483648.0));  // uint32 -> double, exact
  const __m256d nf = _mm256_sub_pd(_mm256_mul_pd(area, qd), _mm256_mul_pd(sd, sd));
  const __m256d positive = _mm256_cmp_pd(nf, _mm256_setzero_pd(), _CMP_GT_OQ);
  const __m128 vnf = _mm256_cvtpd_ps(_mm256_div_pd(_mm256_set1_pd(1.0), _mm256_sqrt_pd(nf)));
  const __m256d busy = _mm256_cmp_pd(_mm256_mul_pd(area, _mm256_cvtps_pd(vnf)), _mm256_set1_pd(1e-1), _CMP_LT_OQ);
  okMask = _mm256_movemask_pd(_mm256_and_pd(positive, busy));
  return vnf;
}

template <int kStep>
__attribute__((target("avx2"))) void scanRowAvx2(const RowJob& j, RowResult& out) {
  const CvModel& m = *j.m;
  const int nStages = static_cast<int>(m.stages.size());
  const __m256d area = _mm256_set1_pd(m.normArea);
  const auto* sq = reinterpret_cast<const std::int32_t*>(j.sq);
  bool skipNext = false;  // the previous evaluated window failed the first stage
  alignas(32) float vnf[8];
  alignas(32) double sums[8];
  for (int i0 = 0; i0 < j.positions; i0 += 8) {
    const int lanes = std::min(8, j.positions - i0);
    const std::int32_t* p = j.sum + std::ptrdiff_t(i0) * kStep;
    const std::int32_t* q = sq + std::ptrdiff_t(i0) * kStep;
    const __m256i s8 = rectSum8<kStep>(p, m.norm), q8 = rectSum8<kStep>(q, m.norm);
    int okLo = 0, okHi = 0;
    const __m128 vLo = norm4(_mm256_castsi256_si128(s8), _mm256_castsi256_si128(q8), area, okLo);
    const __m128 vHi = norm4(_mm256_extracti128_si256(s8, 1), _mm256_extracti128_si256(q8, 1), area, okHi);
    const int ok = okLo | (okHi << 4);
    const __m256 v8 = _mm256_set_m128(vHi, vLo);
    _mm256_store_ps(vnf, v8);
    __m256d lo, hi;
    stage8<kStep>(m, m.stages[0], p, v8, lo, hi);
    _mm256_store_pd(sums, lo);
    _mm256_store_pd(sums + 4, hi);
    const __m256d thr0 = _mm256_set1_pd(double(m.stages[0].threshold));
    const int pass0 = _mm256_movemask_pd(_mm256_cmp_pd(lo, thr0, _CMP_GE_OQ)) |
                      (_mm256_movemask_pd(_mm256_cmp_pd(hi, thr0, _CMP_GE_OQ)) << 4);
    // OpenCV's order of evaluation decides which windows exist at all.
    int alive = 0;
    const std::size_t stage0 = m.stages[0].end - m.stages[0].begin;
    for (int k = 0; k < lanes; ++k) {
      if (skipNext) {
        skipNext = false;
        continue;
      }
      ++out.windows;
      if (!((ok >> k) & 1)) continue;
      out.stumps += stage0;
      if (!((pass0 >> k) & 1)) {
        skipNext = true;
        continue;
      }
      alive |= 1 << k;
    }
    if (!alive) continue;
    int accepted = nStages == 1 ? alive : 0;
    for (int s = 1; s < nStages && alive; ++s) {
      const CvStage& st = m.stages[static_cast<std::size_t>(s)];
      const int n = __builtin_popcount(static_cast<unsigned>(alive));
      if (n >= 3) {
        stage8<kStep>(m, st, p, v8, lo, hi);
        _mm256_store_pd(sums, lo);
        _mm256_store_pd(sums + 4, hi);
        const __m256d thr = _mm256_set1_pd(double(st.threshold));
        const int pass = _mm256_movemask_pd(_mm256_cmp_pd(lo, thr, _CMP_GE_OQ)) |
                         (_mm256_movemask_pd(_mm256_cmp_pd(hi, thr, _CMP_GE_OQ)) << 4);
        out.stumps += std::size_t(n) * (st.end - st.begin);
        alive &= pass;
        if (s == nStages - 1) accepted = alive;
      } else {
        for (int k = 0; k < lanes; ++k) {
          if (!((alive >> k) & 1)) continue;
          double score = 0;
          if (runFrom(m, p + std::ptrdiff_t(k) * kStep, vnf[k], s, score, out.stumps) > 0) {
            accepted |= 1 << k;
            sums[k] = score;
          }
        }
        alive = 0;
      }
    }
    for (int k = 0; k < lanes; ++k)
      if ((accepted >> k) & 1) out.hits.emplace_back(i0 + k, sums[k]);
  }
}

#endif

void scanRow(const RowJob& j, RowResult& out) {
#ifdef FUSEDET_HAVE_AVX2_PATH
  if (!j.m->trees && dispatchedVectorLanes() >= 4) {
    if (j.step == 1) scanRowAvx2<1>(j, out);
    else scanRowAvx2<2>(j, out);
    return;
  }
#endif
  scanRowScalar(j, out);
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
  // kReadPad zeros behind each table: the 8-window vector loads may read past the last row (the
  // lanes that do are discarded).
  out.sum.assign(n + kReadPad, 0);
  out.sqsum.assign(n + kReadPad, 0);
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
  out.tilted.assign(n + kReadPad, 0);
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
      tiltedOffset = static_cast<std::ptrdiff_t>(in.sum.size());  // includes the padding
    }
    const CvModel m = compile(c, stride, tiltedOffset);
    const int ystep = sc >= 2 ? 1 : 2;
    const int szwW = std::max(sz.width + 1 - m.winW, 0), szwH = std::max(sz.height + 1 - m.winH, 0);
    const int winW = cvRoundF(float(m.winW) * sc), winH = cvRoundF(float(m.winH) * sc);
    const int rows = (szwH + ystep - 1) / ystep;
    std::vector<std::vector<RawHit>> hits(static_cast<std::size_t>(rows));
    std::vector<std::size_t> windows(static_cast<std::size_t>(rows), 0), stumps(static_cast<std::size_t>(rows), 0);
    std::vector<RowResult> results(static_cast<std::size_t>(rows));
    auto row = [&](int ri) {
      const int y = ri * ystep;
      RowJob job;
      job.m = &m;
      job.sum = sumBase + y * stride;
      job.sq = in.sqsum.data() + y * stride;
      job.positions = (szwW + ystep - 1) / ystep;
      job.step = ystep;
      RowResult& res = results[static_cast<std::size_t>(ri)];
      scanRow(job, res);
      auto& h = hits[static_cast<std::size_t>(ri)];
      for (const auto& [i, score] : res.hits) {
        const int x = i * ystep;
        h.push_back(RawHit{Box{cvRoundF(float(x) * sc) * toRefX, cvRoundF(float(y) * sc) * toRefY, winW * toRefX,
                               winH * toRefY},
                           score, static_cast<int>(si)});
      }
      windows[static_cast<std::size_t>(ri)] = res.windows;
      stumps[static_cast<std::size_t>(ri)] = res.stumps;
    };
    if (params.threads == 1) {
      for (int ri = 0; ri < rows; ++ri) row(ri);
    } else {
      auto run = [&] {
        parallelFor(tbb::blocked_range<int>(0, rows), [&](const tbb::blocked_range<int>& r) {
          for (int ri = r.begin(); ri != r.end(); ++ri) row(ri);
        });
      };
      if (params.threads > 1) {
        tbb::task_arena arena(std::min(params.threads, tbb::info::default_concurrency()));
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
