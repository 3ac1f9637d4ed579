// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/window_scanner.h"

#include <tbb/blocked_range.h>
#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <limits>
#include <stdexcept>
#include <tuple>
#include <utility>

#include "fusedet/boost/float_cut.h"
#include "fusedet/boost/parallel_for.h"
#include "fusedet/boost/vector_path.h"

// GCC only: the vector copies get their instruction sets from `#pragma GCC target`, which clang
// (the fuzz build, tests/fuzz) does not apply, so it refuses the intrinsics; clang takes the
// scalar path, which the vector lanes equal bit for bit.
#if defined(__x86_64__) && defined(__GNUC__) && !defined(__clang__)
#include <immintrin.h>
#define FUSEDET_HAVE_AVX2_GRID_PATH 1
#endif
// arm64: NEON is part of every AArch64 CPU, its intrinsics need no target pragma.
#if defined(__aarch64__) && defined(__GNUC__)
#include <arm_neon.h>
#define FUSEDET_HAVE_NEON_GRID_PATH 1
#endif
#if defined(FUSEDET_HAVE_AVX2_GRID_PATH) || defined(FUSEDET_HAVE_NEON_GRID_PATH)
#define FUSEDET_HAVE_VECTOR_GRID_PATH 1
#endif

namespace fusedet::boosting {

namespace {

int roundHalfUp(double v) { return static_cast<int>(std::floor(v + 0.5)); }

// One stump laid out for one scale: its rectangles' corners as offsets from the window's origin in
// its grid, (x0,y0) (x1,y0) (x0,y1) (x1,y1). black = rect 0 (+ rect 1 for the checker); white =
// rect 2, minus black when rect 2 is the outer rectangle (FeatureLayout's rule).
// Two-rectangle features whose halves share an edge (types a and b): the white rectangle's two
// corners on that edge are the black one's, loaded once by the vector paths.
enum class SharedEdge : std::uint8_t { kNone, kColumn /* white's left = black's right */, kRow /* white's top = black's bottom */ };

struct GridStump {
  int grid = 0;
  bool intGrid = false;  // the grid's tables are int32 (IntegralGrid::exactInt)
  bool checker = false;
  bool whiteIsRest = false;
  SharedEdge shared = SharedEdge::kNone;
  std::array<std::array<std::int32_t, 4>, 3> ofs{};
  double blackArea = 1, whiteArea = 1;
  // The vector paths' quick form: value' = black * invBlackArea - white * invWhiteArea differs
  // from the exact value (divisions) by less than the stump's margin m (setQuickBounds()), and the
  // exact value rounded to float is below `threshold` iff the exact value is below `cut`
  // (float_cut.h). So value' < quickBelow = cut - m decides "below", value' > quickAbove = cut + m
  // decides "not below"; the rare windows between (and NaN values) are computed exactly.
  double invBlackArea = 1, invWhiteArea = 1, quickBelow = 0, quickAbove = 0;
  float threshold = 0;
  double left = 0, right = 0;
  // The vector paths' early stage decision (setEarlyBounds()): after this stump, a stage sum below
  // rejectBelow fails the stage whatever the stumps still to come add, one above acceptAbove passes it.
  double rejectBelow = -std::numeric_limits<double>::infinity();
  double acceptAbove = std::numeric_limits<double>::infinity();
};

// The margin m of one stump (see GridStump) whose layer's values lie within +-bound (its slot's
// IntegralGrid::bounds: finite values; a window whose rectangles hold a NaN or an infinity has a NaN
// or infinite black or white and is decided the same way on both paths or left to the exact one).
// For black/blackArea = a, white/whiteArea = b: a * (1/area) in double is within 2u|a| of a (u =
// 2^-53: the rounded reciprocal, the product), the exact path's quotient within u|a|, and each
// difference within u of its result, so |value' - value| <= 6u(|a'| + |b'|) (a', b' the products;
// second-order terms included). A rectangle sum from a double table is within 4(w + h + 3)u * bound
// * w * h of the exact sum (the tables' recurrence over a w x h grid, then three operations), at
// most `bound` while 4(w + h + 16)u * w * h <= 1 (every camera-size grid): then |a'| <= bound *
// (black rectangles' area + 4 per rectangle) / blackArea, likewise |b'| (the white rectangle, plus
// the black ones where white is the rest), and m = 16u(|a'| + |b'|) bounds, plus 2^-1000 for
// results in the subnormal range, with room to spare. Otherwise (quick decisions off, an infinite
// bound, a grid too large) m = +inf: every window takes the exact path. Since d < fl(x) <=> d < x
// for doubles d and any real x, cut -+ m rounded to double keeps the guarantee.
// Sets z.quickBelow and z.quickAbove.
void setQuickBounds(GridStump& z, const IntegralGrid& gr, int slot, const FeatureLayout& lay, double cut, bool quick) {
  const double u = 0x1p-53, pixels = double(gr.width) * double(gr.height);
  const double bound = gr.bounds[static_cast<std::size_t>(slot)];
  double m = std::numeric_limits<double>::infinity();
  if (quick && std::isfinite(bound) && 4.0 * (gr.width + gr.height + 16) * u * pixels <= 1.0) {
    auto area = [](const PixelRect& r) { return double(r.x1 - r.x0) * double(r.y1 - r.y0); };
    double black = 0;
    for (int k = 0; k < lay.blackCount; ++k) black += area(lay.rects[static_cast<std::size_t>(k)]) + 4;
    const double white = area(lay.rects[static_cast<std::size_t>(lay.blackCount)]) + 4 + (lay.whiteIsRest ? black : 0);
    m = 16 * u * bound * (black / lay.blackArea + white / lay.whiteArea) * (1 + 0x1p-20) + 0x1p-1000;
  }
  z.quickBelow = cut - m;
  z.quickAbove = cut + m;
}

// Sets rejectBelow and acceptAbove of the stumps [begin, end) of one stage (threshold t): after stump
// k the sum still gains between lo_k and hi_k, the sums of min(left, right) and max(left, right) of
// the stumps behind k. A sum s_k < t - hi_k - m ends below t, s_k > t - lo_k + m at or above it,
// where m covers the rounding: every partial sum lies within A = sum of max(|left|, |right|), each of
// the n additions still to come and of the bounds' own is off by at most u * (|t| + A) (u = 2^-53),
// and m = 4 (n + 2) u (|t| + A) is twice that. The last stage accepts nothing early (its sum is the
// window's score), and the last stump decides nothing (its stage sum is complete).
void setEarlyBounds(std::vector<GridStump>& stumps, std::size_t begin, std::size_t end, double t, bool lastStage) {
  double A = 0;
  for (std::size_t k = begin; k < end; ++k) A += std::max(std::fabs(stumps[k].left), std::fabs(stumps[k].right));
  const double m = 4.0 * double(end - begin + 2) * 0x1p-53 * (std::fabs(t) + A);
  double lo = 0, hi = 0;
  for (std::size_t k = end - 1; k-- > begin;) {
    lo += std::min(stumps[k + 1].left, stumps[k + 1].right);
    hi += std::max(stumps[k + 1].left, stumps[k + 1].right);
    stumps[k].rejectBelow = t - hi - m;
    if (!lastStage) stumps[k].acceptAbove = t - lo + m;
  }
}

std::atomic<bool> gQuickDecisions{true};

constexpr int kSpanStride = -1;  // GridScale::colStride of narrow irregular rows
constexpr std::size_t kBand = 48;  // window columns per tile
// Stage 0's whole steps per pass over a row, stump by stump (vector_stages.inc, rowStageSums()):
// a band's row in four-lane steps.
constexpr std::size_t kMaxRowSteps = kBand / 4;
constexpr std::size_t kTileWindows = 512;  // windows per tile (rows of a band): breadth-first unit
// A later stage's steps per pass, stump by stump (laterStage()): a tile's windows in four-lane steps.
constexpr std::size_t kMaxLaterSteps = kTileWindows / 4;

struct GridStage {
  std::uint32_t begin = 0, end = 0;
  double threshold = 0;
  std::uint32_t grids = 0;  // bit g set: a stump reads grid g
};

struct GridScale {
  ScaleWindows win;
  std::vector<std::vector<std::int32_t>> colOfs, rowOfs;  // per grid, per position
  // Per grid: d > 0 when neighbouring windows' origins are d values apart along the whole row
  // (stage 0 loads their corners from the first one's, each path as its Lanes::corners() can:
  // whole vectors, every other value, a few loads and shuffles); kSpanStride when any eight
  // neighbours' origins lie within 16 values of the first one's and any four within 8 (two loads
  // and a lane permutation), else 0 (lane by lane).
  std::vector<int> colStride;
  std::vector<GridStump> stumps;
  std::vector<GridStage> stages;
};

// slots[l]: where layer l's sums live.
GridScale planScale(const Cascade& c, const IntegralGrids& in, const std::vector<SlotRef>& slots,
                    ScaleWindows win) {
  GridScale sp;
  const bool quick = gQuickDecisions.load(std::memory_order_relaxed);  // off: every stump exact
  const int W = in.refWidth(), H = in.refHeight();
  const std::size_t ng = in.grids().size();
  sp.colOfs.resize(ng);
  sp.rowOfs.resize(ng);
  sp.colStride.reserve(ng);
  std::vector<std::array<int, 2>> lwSize(ng);
  for (std::size_t g = 0; g < ng; ++g) {
    const IntegralGrid& gr = in.grids()[g];
    LayerIntegral geometry;  // the mapping rule needs only the layer's size (and name for errors)
    geometry.name = gr.slots.front().name;
    geometry.width = gr.width;
    geometry.height = gr.height;
    lwSize[g] = layerWindowSize(geometry, W, H, win.winW, win.winH);
    const double sx = double(gr.width) / W, sy = double(gr.height) / H;
    sp.colOfs[g].reserve(win.xs.size() + 8);
    sp.rowOfs[g].reserve(win.ys.size());
    for (int x : win.xs) sp.colOfs[g].push_back(std::clamp(roundHalfUp(x * sx), 0, gr.width - lwSize[g][0]));
    const auto& co = sp.colOfs[g];
    sp.colStride.push_back(0);
    if (co.size() > 1 && co[1] > co[0]) {
      bool regular = true;
      for (std::size_t i = 1; i < co.size() && regular; ++i) regular = co[i] - co[i - 1] == co[1] - co[0];
      if (regular) sp.colStride.back() = co[1] - co[0];
    }
    if (sp.colStride.back() == 0) {  // offsets grow with the column: a window's span is its eighth's
      bool narrow = true;
      for (std::size_t i = 0; i < co.size() && narrow; ++i)
        narrow = co[std::min(i + 7, co.size() - 1)] - co[i] <= 15 && co[std::min(i + 3, co.size() - 1)] - co[i] <= 7;
      if (narrow) sp.colStride.back() = kSpanStride;
    }
    sp.colOfs[g].insert(sp.colOfs[g].end(), 8, sp.colOfs[g].back());  // padding for eight-lane loads
    for (int y : win.ys) {
      const int row = std::clamp(roundHalfUp(y * sy), 0, gr.height - lwSize[g][1]);
      sp.rowOfs[g].push_back(static_cast<std::int32_t>(row * gr.pitch));
    }
  }
  std::size_t stumps = 0;
  for (const Stage& st : c.stages) stumps += st.stumps.size();
  sp.stumps.reserve(stumps);  // built in place: a GridStump is a few cache lines
  sp.stages.reserve(c.stages.size());
  for (const Stage& st : c.stages) {
    GridStage gs{static_cast<std::uint32_t>(sp.stumps.size()), 0, st.threshold};
    for (const Stump& t : st.stumps) {
      const Feature& f = c.features[static_cast<std::size_t>(t.feature)];
      const SlotRef ref = slots[static_cast<std::size_t>(f.layer)];
      const IntegralGrid& gr = in.grids()[static_cast<std::size_t>(ref.grid)];
      const auto& lw = lwSize[static_cast<std::size_t>(ref.grid)];
      const FeatureLayout lay = layoutFeature(f.type, featureRectInWindow(f, lw[0], lw[1]));
      const std::ptrdiff_t slot0 = ref.slot * gr.stride;
      auto corners = [&](const PixelRect& r) {
        return std::array<std::int32_t, 4>{static_cast<std::int32_t>(slot0 + r.y0 * gr.pitch + r.x0),
                                           static_cast<std::int32_t>(slot0 + r.y0 * gr.pitch + r.x1),
                                           static_cast<std::int32_t>(slot0 + r.y1 * gr.pitch + r.x0),
                                           static_cast<std::int32_t>(slot0 + r.y1 * gr.pitch + r.x1)};
      };
      GridStump& z = sp.stumps.emplace_back();
      z.grid = ref.grid;
      z.intGrid = gr.exactInt;
      z.checker = lay.blackCount == 2;
      z.whiteIsRest = lay.whiteIsRest;
      z.ofs[0] = corners(lay.rects[0]);
      if (z.checker) z.ofs[1] = corners(lay.rects[1]);
      z.ofs[2] = corners(lay.rects[static_cast<std::size_t>(lay.blackCount)]);
      if (!z.checker && !z.whiteIsRest) {
        if (z.ofs[2][0] == z.ofs[0][1] && z.ofs[2][2] == z.ofs[0][3]) z.shared = SharedEdge::kColumn;
        if (z.ofs[2][0] == z.ofs[0][2] && z.ofs[2][1] == z.ofs[0][3]) z.shared = SharedEdge::kRow;
      }
      z.blackArea = lay.blackArea;
      z.whiteArea = lay.whiteArea;
      z.invBlackArea = 1.0 / lay.blackArea;
      z.invWhiteArea = 1.0 / lay.whiteArea;
      z.threshold = static_cast<float>(t.threshold);
      setQuickBounds(z, gr, ref.slot, lay, floatCut(z.threshold), quick);
      z.left = t.left;
      z.right = t.right;
    }
    gs.end = static_cast<std::uint32_t>(sp.stumps.size());
    if (gs.end > gs.begin) setEarlyBounds(sp.stumps, gs.begin, gs.end, st.threshold, &st == &c.stages.back());
    for (std::uint32_t k = gs.begin; k < gs.end; ++k) gs.grids |= 1u << sp.stumps[k].grid;
    sp.stages.push_back(gs);
  }
  sp.win = std::move(win);
  return sp;
}

// Windows of one chunk in structure-of-arrays form, compacted in place after each stage. Offsets:
// the window's origin in each grid. kPad entries of padding behind the last window hold a valid
// window so that vector lanes past the end read inside the grids.
struct WindowList {
  static constexpr std::size_t kPad = 8;  // the widest vector path's lanes
  std::size_t cap = 0, grids = 0;
  std::vector<std::int32_t> off;  // grids x cap
  std::vector<std::int32_t> xi, yi;
  std::vector<double> score;
  void reserve(std::size_t windows, std::size_t nGrids) {
    cap = windows + kPad;
    grids = nGrids;
    off.assign(cap * grids, 0);
    xi.assign(cap, 0);
    yi.assign(cap, 0);
    score.assign(cap, 0);
  }
  std::int32_t* offsets(std::size_t g) { return off.data() + g * cap; }
  // Inlined into the vector loops: an out-of-line call from there into baseline (SSE) code costs a
  // vector-state transition per stage.
  [[gnu::always_inline]] inline void pad(std::size_t n) {
    for (std::size_t g = 0; g < grids; ++g)
      for (std::size_t k = n; k < n + kPad; ++k) offsets(g)[k] = n ? offsets(g)[0] : 0;
  }
  void keep(std::size_t from, std::size_t to, double s) {
    for (std::size_t g = 0; g < grids; ++g) offsets(g)[to] = offsets(g)[from];
    xi[to] = xi[from];
    yi[to] = yi[from];
    score[to] = s;
  }
};

// Rectangle sum at p (a window's origin in its grid): double tables in featureValue()'s order;
// int32 tables (8-bit layers) exactly, so the double it converts to is the same.
inline double rectSum(const double* p, const std::array<std::int32_t, 4>& o) {
  return p[o[3]] - p[o[1]] - p[o[2]] + p[o[0]];
}
inline double rectSum(const std::int32_t* p, const std::array<std::int32_t, 4>& o) {
  return static_cast<double>(std::int64_t(p[o[3]]) - p[o[1]] - p[o[2]] + p[o[0]]);
}

// The value of one stump on one window before it is rounded to float, as featureValue()
// computes it (see GridStump).
template <class T>
inline double stumpValue(const GridStump& z, const T* p) {
  double black = rectSum(p, z.ofs[0]);
  if (z.checker) black = black + rectSum(p, z.ofs[1]);
  double white = rectSum(p, z.ofs[2]);
  if (z.whiteIsRest) white = white - black;
  return black / z.blackArea - white / z.whiteArea;
}

// One stage on windows [0, n) of the list, one window at a time; keeps those that pass.
std::size_t stageScalar(const GridScale& sp, const GridStage& st, const void* const* grids, WindowList& l,
                        std::size_t n) {
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    double sum = 0;
    for (std::uint32_t k = st.begin; k < st.end; ++k) {
      const GridStump& z = sp.stumps[k];
      const std::int32_t o = l.offsets(static_cast<std::size_t>(z.grid))[i];
      const double value = z.intGrid ? stumpValue(z, static_cast<const std::int32_t*>(grids[z.grid]) + o)
                                     : stumpValue(z, static_cast<const double*>(grids[z.grid]) + o);
      const auto v = static_cast<float>(value);
      sum += v < z.threshold ? z.left : z.right;
    }
    if (!(sum < st.threshold)) l.keep(i, kept++, sum);
  }
  l.pad(kept);
  return kept;
}

#ifdef FUSEDET_HAVE_VECTOR_GRID_PATH
constexpr std::size_t kMaxVectorGrids = 8;
constexpr double kInf = std::numeric_limits<double>::infinity();

// How a vector path loads the corners of one step's windows in one grid (GridScale::colStride):
// lane by lane, or from the first window's origin for origins 1, 2, 3 or more values apart, or in
// span mode. Each path's Lanes::corners<Load>() does what its instruction set can; the stage loops
// pick the mode once per stump, so that no corner load branches on it.
enum class Load : std::uint8_t { kLanes, kOne, kTwo, kThree, kWide, kSpan };
constexpr Load loadOf(int stride) {
  if (stride == kSpanStride) return Load::kSpan;
  if (stride <= 0) return Load::kLanes;
  return stride == 1 ? Load::kOne : stride == 2 ? Load::kTwo : stride == 3 ? Load::kThree : Load::kWide;
}

// The vector stage loops (vector_stages.inc) are written once against a `Lanes` type - the vector
// width and its operations - and compiled once per instruction set, each copy under its own target
// so that the AVX2 copy holds no AVX-512 instruction. Every lane does the scalar path's operations
// in the same order (add/sub/div, no FMA), so the lanes equal stageScalar() bit for bit.

// Tables for compressing four lanes (AVX2 and NEON have no compress instruction): for each mask of
// lanes to keep, the source lane of each destination lane, as bytes of 32-bit lanes
// (kCompressBytes) and, for AVX2, as 32-bit halves of 64-bit lanes (kCompressPairs).
constexpr std::array<int, 4> compressOrder(int keep) {
  std::array<int, 4> src{0, 0, 0, 0};
  int n = 0;
  for (int k = 0; k < 4; ++k)
    if ((keep >> k) & 1) src[static_cast<std::size_t>(n++)] = k;
  return src;
}
constexpr std::array<std::array<std::int8_t, 16>, 16> kCompressBytes = [] {
  std::array<std::array<std::int8_t, 16>, 16> t{};
  for (int m = 0; m < 16; ++m)
    for (int d = 0; d < 4; ++d)
      for (int b = 0; b < 4; ++b)
        t[static_cast<std::size_t>(m)][static_cast<std::size_t>(4 * d + b)] =
            static_cast<std::int8_t>(4 * compressOrder(m)[static_cast<std::size_t>(d)] + b);
  return t;
}();
#ifdef FUSEDET_HAVE_AVX2_GRID_PATH
constexpr std::array<std::array<std::int32_t, 8>, 16> kCompressPairs = [] {
  std::array<std::array<std::int32_t, 8>, 16> t{};
  for (int m = 0; m < 16; ++m)
    for (int d = 0; d < 4; ++d)
      for (int h = 0; h < 2; ++h)
        t[static_cast<std::size_t>(m)][static_cast<std::size_t>(2 * d + h)] = 2 * compressOrder(m)[static_cast<std::size_t>(d)] + h;
  return t;
}();

#pragma GCC push_options
#pragma GCC target("avx2")
namespace avx2 {
// Four windows per step: int32 offsets and table values in __m128i, doubles in __m256d.
struct Lanes {
  static constexpr std::size_t kCount = 4;
  using Ints = __m128i;
  using Doubles = __m256d;
  static Ints loadInts(const std::int32_t* p) { return _mm_loadu_si128(reinterpret_cast<const __m128i*>(p)); }
  static void storeInts(std::int32_t* p, Ints v) { _mm_storeu_si128(reinterpret_cast<__m128i*>(p), v); }
  static Ints splat(std::int32_t v) { return _mm_set1_epi32(v); }
  static Ints add(Ints a, Ints b) { return _mm_add_epi32(a, b); }
  static Ints sub(Ints a, Ints b) { return _mm_sub_epi32(a, b); }
  static Ints iota(std::int32_t first) { return _mm_add_epi32(_mm_set1_epi32(first), _mm_setr_epi32(0, 1, 2, 3)); }
  // The lanes whose bit is set in `keep`, moved to the front (in order; the rest is don't-care):
  // byte shuffles from a table of the 16 masks.
  static Ints compress(Ints v, int keep) {
    return _mm_shuffle_epi8(v, _mm_loadu_si128(reinterpret_cast<const __m128i*>(kCompressBytes[keep].data())));
  }
  static Doubles compress(Doubles v, int keep) {
    const __m256i idx = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(kCompressPairs[keep].data()));
    return _mm256_castps_pd(_mm256_permutevar8x32_ps(_mm256_castpd_ps(v), idx));
  }
  // The windows' origins for corners(): in memory, for scalar loads, and in span mode (all four
  // within 8 values of b, stride kSpanStride) the permutation that picks them from two loads: per
  // lane the 32-bit halves of its value in a load of four (spanPairs) and whether that is the
  // second load (spanHigh, all bits set).
  struct Index {
    alignas(16) std::int32_t k[4];
    __m256i spanPairs;
    __m256d spanHigh;
  };
  static Index index(Ints o, int stride) {
    Index i;
    _mm_store_si128(reinterpret_cast<__m128i*>(i.k), o);
    if (stride == kSpanStride) {
      const __m256i k64 = _mm256_cvtepi32_epi64(o);
      const __m256i low = _mm256_and_si256(k64, _mm256_set1_epi64x(3));
      // lane value 2 * (k & 3) in the low half, + 1 in the high half of each 64-bit lane
      i.spanPairs = _mm256_or_si256(_mm256_slli_epi64(low, 1), _mm256_slli_epi64(_mm256_add_epi64(_mm256_slli_epi64(low, 1), _mm256_set1_epi64x(1)), 32));
      i.spanHigh = _mm256_castsi256_pd(_mm256_cmpgt_epi64(k64, _mm256_set1_epi64x(3)));
    }
    return i;
  }
  // Corner values of the windows: lane by lane (origins b + o.k[i], stride 0), or for neighbours
  // whose origins are `stride` values apart (stage 0) from the first one's origin b with a few
  // loads and shuffles, or in span mode picked from two loads. The same values every way. Scalar
  // loads beat AVX2's gather instructions (measured: bench/README.md).
  template <Load kMode>
  [[gnu::always_inline]] static Doubles corners(const double* b, const Index& o, int stride) {
    if constexpr (kMode == Load::kOne) return _mm256_loadu_pd(b);
    if constexpr (kMode == Load::kTwo) {
      const __m256d lo = _mm256_loadu_pd(b), hi = _mm256_loadu_pd(b + 4);  // p0..p3, p4..p7
      return _mm256_permute4x64_pd(_mm256_unpacklo_pd(lo, hi), 0xD8);        // p0 p4 p2 p6 -> p0 p2 p4 p6
    }
    if constexpr (kMode == Load::kThree)  // p0 p6 p3 p9 -> p0 p3 p6 p9
      return _mm256_permute4x64_pd(_mm256_shuffle_pd(_mm256_loadu_pd(b), _mm256_loadu_pd(b + 6), 0xC), 0xD8);
    if constexpr (kMode == Load::kWide) {  // [p0 . p2d .] and [pd . p3d .]
      const __m256d a = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(b)), _mm_loadu_pd(b + 2 * stride), 1);
      const __m256d c = _mm256_insertf128_pd(_mm256_castpd128_pd256(_mm_loadu_pd(b + stride)), _mm_loadu_pd(b + 3 * stride), 1);
      return _mm256_unpacklo_pd(a, c);  // p0 pd p2d p3d
    }
    if constexpr (kMode == Load::kSpan) {
      const __m256 lo = _mm256_castpd_ps(_mm256_loadu_pd(b)), hi = _mm256_castpd_ps(_mm256_loadu_pd(b + 4));
      return _mm256_blendv_pd(_mm256_castps_pd(_mm256_permutevar8x32_ps(lo, o.spanPairs)),
                              _mm256_castps_pd(_mm256_permutevar8x32_ps(hi, o.spanPairs)), o.spanHigh);
    }
    if constexpr (kMode == Load::kLanes) {
      const __m128d lo = _mm_loadh_pd(_mm_load_sd(b + o.k[0]), b + o.k[1]);
      const __m128d hi = _mm_loadh_pd(_mm_load_sd(b + o.k[2]), b + o.k[3]);
      return _mm256_insertf128_pd(_mm256_castpd128_pd256(lo), hi, 1);
    }
  }
  template <Load kMode>
  [[gnu::always_inline]] static Ints corners(const std::int32_t* b, const Index& o, int stride) {
    if constexpr (kMode == Load::kOne) return loadInts(b);
    if constexpr (kMode == Load::kTwo) {
      const __m256i v = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(b));
      return _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(v, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
    }
    if constexpr (kMode == Load::kThree || kMode == Load::kWide)
      return _mm_setr_epi32(b[0], b[stride], b[2 * stride], b[3 * stride]);
    if constexpr (kMode == Load::kSpan || kMode == Load::kLanes)
      return _mm_setr_epi32(b[o.k[0]], b[o.k[1]], b[o.k[2]], b[o.k[3]]);
  }
  static Doubles toDouble(Doubles v) { return v; }
  static Doubles toDouble(Ints v) { return _mm256_cvtepi32_pd(v); }
  static Doubles zero() { return _mm256_setzero_pd(); }
  static Doubles splat(double v) { return _mm256_set1_pd(v); }
  static Doubles add(Doubles a, Doubles b) { return _mm256_add_pd(a, b); }
  static Doubles sub(Doubles a, Doubles b) { return _mm256_sub_pd(a, b); }
  static Doubles div(Doubles a, Doubles b) { return _mm256_div_pd(a, b); }
  static Doubles mul(Doubles a, Doubles b) { return _mm256_mul_pd(a, b); }
  static Doubles roundToFloat(Doubles v) { return _mm256_cvtps_pd(_mm256_cvtpd_ps(v)); }
  // Per-lane truth values: all bits of a lane set where true.
  using Mask = __m256d;
  static Mask less(Doubles a, Doubles b) { return _mm256_cmp_pd(a, b, _CMP_LT_OQ); }
  static Mask greater(Doubles a, Doubles b) { return _mm256_cmp_pd(a, b, _CMP_GT_OQ); }
  static Mask either(Mask a, Mask b) { return _mm256_or_pd(a, b); }
  static bool all(Mask m) { return _mm256_movemask_pd(m) == 0xF; }
  static Mask select(Mask pick, Mask a, Mask b) { return _mm256_blendv_pd(b, a, pick); }  // pick ? a : b
  // lt ? left : right, per lane.
  static Doubles choose(Mask lt, double left, double right) { return _mm256_blendv_pd(splat(right), splat(left), lt); }
  // Bit k set where !(sum[k] < threshold): window k passes the stage.
  static int passMask(Doubles sum, double threshold) {
    return _mm256_movemask_pd(_mm256_cmp_pd(sum, splat(threshold), _CMP_NLT_UQ));
  }
  static void store(double* p, Doubles v) { _mm256_storeu_pd(p, v); }
};
#include "vector_stages.inc"
}  // namespace avx2
#pragma GCC pop_options

#pragma GCC push_options
#pragma GCC target("avx512f,avx512vl")
// GCC 12's AVX-512 intrinsics start from undefined vectors, which -W(maybe-)uninitialized flags.
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
namespace avx512 {
// Eight windows per step: int32 offsets and table values in __m256i, doubles in __m512d.
struct Lanes {
  static constexpr std::size_t kCount = 8;
  using Ints = __m256i;
  using Doubles = __m512d;
  static Ints loadInts(const std::int32_t* p) { return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(p)); }
  static void storeInts(std::int32_t* p, Ints v) { _mm256_storeu_si256(reinterpret_cast<__m256i*>(p), v); }
  static Ints splat(std::int32_t v) { return _mm256_set1_epi32(v); }
  static Ints add(Ints a, Ints b) { return _mm256_add_epi32(a, b); }
  static Ints sub(Ints a, Ints b) { return _mm256_sub_epi32(a, b); }
  static Ints iota(std::int32_t first) {
    return _mm256_add_epi32(_mm256_set1_epi32(first), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
  }
  static Ints compress(Ints v, int keep) { return _mm256_maskz_compress_epi32(static_cast<__mmask8>(keep), v); }
  static Doubles compress(Doubles v, int keep) { return _mm512_maskz_compress_pd(static_cast<__mmask8>(keep), v); }
  struct Index {
    alignas(32) std::int32_t k[8];
    Ints v;  // the same, for the span mode's permutation
  };
  static Index index(Ints o, int /*stride*/) {
    Index i;
    _mm256_store_si256(reinterpret_cast<__m256i*>(i.k), o);
    i.v = o;
    return i;
  }
  // As avx2::Lanes::corners (eight scalar loads beat AVX-512's gather instructions too, measured:
  // bench/README.md); kSpanStride: the eight values lie within 16 of b (o = offsets from b),
  // picked from two loads by a permutation; strides above 2 lane by lane (o relative to b).
  template <Load kMode>
  [[gnu::always_inline]] static Doubles corners(const double* b, const Index& o, int /*stride*/) {
    if constexpr (kMode == Load::kOne) return _mm512_loadu_pd(b);
    if constexpr (kMode == Load::kTwo)
      return _mm512_permutex2var_pd(_mm512_loadu_pd(b), _mm512_setr_epi64(0, 2, 4, 6, 8, 10, 12, 14),
                                    _mm512_loadu_pd(b + 8));
    if constexpr (kMode == Load::kSpan)
      return _mm512_permutex2var_pd(_mm512_loadu_pd(b), _mm512_cvtepi32_epi64(o.v), _mm512_loadu_pd(b + 8));
    if constexpr (kMode == Load::kLanes || kMode == Load::kThree || kMode == Load::kWide) {
      const __m128d a = _mm_loadh_pd(_mm_load_sd(b + o.k[0]), b + o.k[1]);
      const __m128d c = _mm_loadh_pd(_mm_load_sd(b + o.k[2]), b + o.k[3]);
      const __m128d d = _mm_loadh_pd(_mm_load_sd(b + o.k[4]), b + o.k[5]);
      const __m128d e = _mm_loadh_pd(_mm_load_sd(b + o.k[6]), b + o.k[7]);
      const __m256d lo = _mm256_insertf128_pd(_mm256_castpd128_pd256(a), c, 1);
      const __m256d hi = _mm256_insertf128_pd(_mm256_castpd128_pd256(d), e, 1);
      return _mm512_insertf64x4(_mm512_castpd256_pd512(lo), hi, 1);
    }
  }
  template <Load kMode>
  [[gnu::always_inline]] static Ints corners(const std::int32_t* b, const Index& o, int /*stride*/) {
    if constexpr (kMode == Load::kOne) return loadInts(b);
    if constexpr (kMode == Load::kTwo) {
      const __m512i v = _mm512_loadu_si512(b);
      return _mm512_castsi512_si256(
          _mm512_permutexvar_epi32(_mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 1, 3, 5, 7, 9, 11, 13, 15), v));
    }
    if constexpr (kMode == Load::kSpan)
      return _mm512_castsi512_si256(_mm512_permutexvar_epi32(_mm512_castsi256_si512(o.v), _mm512_loadu_si512(b)));
    if constexpr (kMode == Load::kLanes || kMode == Load::kThree || kMode == Load::kWide)
      return _mm256_setr_epi32(b[o.k[0]], b[o.k[1]], b[o.k[2]], b[o.k[3]], b[o.k[4]], b[o.k[5]], b[o.k[6]], b[o.k[7]]);
  }
  static Doubles toDouble(Doubles v) { return v; }
  static Doubles toDouble(Ints v) { return _mm512_cvtepi32_pd(v); }
  static Doubles zero() { return _mm512_setzero_pd(); }
  static Doubles splat(double v) { return _mm512_set1_pd(v); }
  static Doubles add(Doubles a, Doubles b) { return _mm512_add_pd(a, b); }
  static Doubles sub(Doubles a, Doubles b) { return _mm512_sub_pd(a, b); }
  static Doubles div(Doubles a, Doubles b) { return _mm512_div_pd(a, b); }
  static Doubles mul(Doubles a, Doubles b) { return _mm512_mul_pd(a, b); }
  static Doubles roundToFloat(Doubles v) { return _mm512_cvtps_pd(_mm512_cvtpd_ps(v)); }
  using Mask = __mmask8;
  static Mask less(Doubles a, Doubles b) { return _mm512_cmp_pd_mask(a, b, _CMP_LT_OQ); }
  static Mask greater(Doubles a, Doubles b) { return _mm512_cmp_pd_mask(a, b, _CMP_GT_OQ); }
  static Mask either(Mask a, Mask b) { return static_cast<Mask>(a | b); }
  static bool all(Mask m) { return m == 0xFF; }
  static Mask select(Mask pick, Mask a, Mask b) { return static_cast<Mask>((pick & a) | (~pick & b)); }
  static Doubles choose(Mask lt, double left, double right) { return _mm512_mask_blend_pd(lt, splat(right), splat(left)); }
  static int passMask(Doubles sum, double threshold) {
    return static_cast<int>(_mm512_cmp_pd_mask(sum, splat(threshold), _CMP_NLT_UQ));
  }
  static void store(double* p, Doubles v) { _mm512_storeu_pd(p, v); }
};
#include "vector_stages.inc"
}  // namespace avx512
#pragma GCC diagnostic pop
#pragma GCC pop_options
namespace four = avx2;  // the four-lane path
#endif

#ifdef FUSEDET_HAVE_NEON_GRID_PATH
namespace neon {
#include "neon_lanes.inc"
#include "vector_stages.inc"
}  // namespace neon
namespace four = neon;
#endif

// The dispatched path (vector_path.h): 8, 4 or 1 lanes; scalar for more grids than the vector
// loops hold.
int vectorLanes(std::size_t grids) { return grids > kMaxVectorGrids ? 1 : dispatchedVectorLanes(); }
#endif

// Stage 0 one window at a time (the reference form): the list of every window, then its first stage.
std::size_t firstStageScalar(const GridScale& sp, const void* const* grids, std::size_t x0, std::size_t x1,
                             std::size_t y0, std::size_t y1, WindowList& l) {
  std::size_t n = 0;
  for (std::size_t yi = y0; yi < y1; ++yi)
    for (std::size_t xi = x0; xi < x1; ++xi, ++n) {
      for (std::size_t g = 0; g < l.grids; ++g) l.offsets(g)[n] = sp.rowOfs[g][yi] + sp.colOfs[g][xi];
      l.xi[n] = static_cast<std::int32_t>(xi);
      l.yi[n] = static_cast<std::int32_t>(yi);
    }
  l.pad(n);
  return stageScalar(sp, sp.stages.front(), grids, l, n);
}

// Runs `work` (parallel loops inside) on ScanParams::threads threads: an arena of that many (> 1),
// or with 0 the calling thread's own arena (all cores).
template <class Work>
void onThreads(int threads, Work&& work) {
  if (threads > 1) {
    tbb::task_arena arena(std::min(threads, tbb::info::default_concurrency()));
    arena.execute(work);
  } else {
    work();
  }
}

// One tile: rows [y0, y1) x columns [x0, x1) of one scale, breadth-first; hits appended in (row,
// column) order.
void scanTile(const GridScale& sp, const void* const* grids, std::size_t ng, std::size_t x0, std::size_t x1,
              std::size_t y0, std::size_t y1, int scaleIndex, WindowList& l, std::vector<RawHit>& hits,
              std::size_t& stumps) {
  const std::size_t windows = (x1 - x0) * (y1 - y0);
  if (l.cap < windows + WindowList::kPad || l.grids != ng) l.reserve(windows, ng);
#ifdef FUSEDET_HAVE_VECTOR_GRID_PATH
  const int lanes = vectorLanes(ng);
#else
  const int lanes = 1;
#endif
  stumps += windows * (sp.stages.front().end - sp.stages.front().begin);
  std::size_t n = 0;
#ifdef FUSEDET_HAVE_AVX2_GRID_PATH
  if (lanes == 8) n = avx512::firstStage(sp, grids, x0, x1, y0, y1, l);
#endif
#ifdef FUSEDET_HAVE_VECTOR_GRID_PATH
  if (lanes == 4) n = four::firstStage(sp, grids, x0, x1, y0, y1, l);
#endif
  if (lanes == 1) n = firstStageScalar(sp, grids, x0, x1, y0, y1, l);
  for (std::size_t s = 1; s < sp.stages.size() && n > 0; ++s) {
    const GridStage& st = sp.stages[s];
    stumps += n * (st.end - st.begin);
#ifdef FUSEDET_HAVE_AVX2_GRID_PATH
    if (lanes == 8) {
      n = avx512::laterStage(sp, st, grids, l, n);
      continue;
    }
#endif
#ifdef FUSEDET_HAVE_VECTOR_GRID_PATH
    if (lanes == 4) {
      n = four::laterStage(sp, st, grids, l, n);
      continue;
    }
#endif
    n = stageScalar(sp, st, grids, l, n);
  }
  for (std::size_t k = 0; k < n; ++k)
    hits.push_back(RawHit{Box{double(sp.win.xs[static_cast<std::size_t>(l.xi[k])]),
                              double(sp.win.ys[static_cast<std::size_t>(l.yi[k])]), double(sp.win.winW),
                              double(sp.win.winH)},
                          l.score[k], scaleIndex});
}

}  // namespace

void setQuickStumpDecisions(bool enabled) { gQuickDecisions = enabled; }

std::vector<ScaleWindows> windowScales(const Cascade& c, int W, int H, const ScanParams& params) {
  if (!(params.scaleFactor > 1)) throw std::invalid_argument("scale factor must be > 1");
  const ScanParams& p = params;
  const int maxW = p.maxWidth > 0 ? std::min(p.maxWidth, W) : W;
  const int maxH = p.maxHeight > 0 ? std::min(p.maxHeight, H) : H;
  double s0 = 1.0;
  if (p.minWidth > 0 || p.minHeight > 0)
    s0 = std::max(double(p.minWidth) / c.windowWidth, double(p.minHeight) / c.windowHeight);
  std::vector<ScaleWindows> out;
  for (double s = s0;; s *= p.scaleFactor) {
    ScaleWindows sw;
    sw.winW = std::max(1, roundHalfUp(c.windowWidth * s));
    sw.winH = std::max(1, roundHalfUp(c.windowHeight * s));
    if (sw.winW > maxW || sw.winH > maxH) break;
    if (sw.winW < p.minWidth || sw.winH < p.minHeight) continue;
    sw.step = std::max(1, roundHalfUp(p.step * s));
    for (int x = 0; x + sw.winW <= W; x += sw.step) sw.xs.push_back(x);
    for (int y = 0; y + sw.winH <= H; y += sw.step) sw.ys.push_back(y);
    out.push_back(std::move(sw));
  }
  return out;
}

std::vector<LayerRequest> layerRequests(const Cascade& c) {
  std::vector<LayerRequest> out;
  for (const std::string& name : c.layers)
    out.push_back(LayerRequest{name, name == layer::kHueDistance ? c.referenceHue : std::nullopt});
  return out;
}

std::vector<std::vector<RawHit>> scanCascades(const std::vector<const Cascade*>& cascades, const IntegralGrids& in,
                                              const ScanParams& params, std::vector<ScanStats>* stats) {
  const std::size_t nc = cascades.size(), ng = in.grids().size();
  for (const IntegralGrid& g : in.grids())
    if (static_cast<double>(g.pitch) * (g.height + 1) >= 2147483647.0)
      throw std::invalid_argument("scan: layers too large for 32-bit offsets (" + std::to_string(g.width) + "x" +
                                  std::to_string(g.height) + " x " + std::to_string(g.slots.size()) + " layers)");
  // Plans of every cascade and scale, made by the threads too (the serial part of a scan is what
  // the second core cannot shorten).
  std::vector<std::vector<GridScale>> plans(nc);
  std::vector<std::vector<SlotRef>> slots(nc);
  std::vector<std::pair<std::size_t, std::size_t>> planJobs;
  for (std::size_t c = 0; c < nc; ++c) {
    const Cascade& cc = *cascades[c];
    if (cc.isOpenCv()) throw std::invalid_argument("scanCascades: OpenCV models scan their own pyramid");
    for (const LayerRequest& r : layerRequests(cc)) slots[c].push_back(in.find(r));
    for (ScaleWindows& w : windowScales(cc, in.refWidth(), in.refHeight(), params)) {
      planJobs.emplace_back(c, plans[c].size());
      plans[c].emplace_back().win = std::move(w);
    }
  }
  auto plan = [&](std::size_t j) {
    const auto [c, s] = planJobs[j];
    plans[c][s] = planScale(*cascades[c], in, slots[c], std::move(plans[c][s].win));
  };
  if (params.threads == 1) {
    for (std::size_t j = 0; j < planJobs.size(); ++j) plan(j);
  } else {
    onThreads(params.threads, [&] { parallelForEach(std::size_t(0), planJobs.size(), plan); });
  }
  // Work items: tiles of one scale of one cascade (a band of window columns, a few rows), all in
  // one index space so that threads share the work across cascades and scales. Ordered by scale,
  // then position, then cascade: the models' tiles over the same part of the image follow each
  // other, so the integral rows one brings into the cache serve the next.
  struct Item {
    std::uint32_t cascade, scale, x0, x1, y0, y1;
    // (scale, top, left, cascade), unique, packed in two words: one comparison each (the sort of
    // thousands of tiles is part of every scan)
    std::pair<std::uint64_t, std::uint64_t> place;
  };
  auto word = [](std::size_t high, std::size_t low) { return std::uint64_t(high) << 32 | low; };
  std::vector<Item> items;
  // Tiles at most: a narrower last band only has taller tiles.
  constexpr std::size_t kFewestRows = std::max<std::size_t>(1, kTileWindows / kBand);
  std::size_t most = 0;
  for (std::size_t c = 0; c < nc; ++c)
    for (const GridScale& sp : plans[c])
      most += (sp.win.xs.size() + kBand - 1) / kBand * ((sp.win.ys.size() + kFewestRows - 1) / kFewestRows);
  items.reserve(most);
  for (std::size_t c = 0; c < nc; ++c)
    for (std::size_t s = 0; s < plans[c].size(); ++s) {
      const ScaleWindows& w = plans[c][s].win;
      for (std::size_t x0 = 0; x0 < w.xs.size(); x0 += kBand) {
        const std::size_t x1 = std::min(w.xs.size(), x0 + kBand);
        const std::size_t rows = std::max<std::size_t>(1, kTileWindows / (x1 - x0));
        for (std::size_t y0 = 0; y0 < w.ys.size(); y0 += rows) {
          const std::size_t y1 = std::min(w.ys.size(), y0 + rows);
          const auto top = static_cast<std::size_t>(w.ys[y0]), left = static_cast<std::size_t>(w.xs[x0]);
          items.push_back(Item{std::uint32_t(c), std::uint32_t(s), std::uint32_t(x0), std::uint32_t(x1),
                               std::uint32_t(y0), std::uint32_t(y1), {word(s, top), word(left, c)}});
        }
      }
    }
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) { return a.place < b.place; });
  std::vector<const void*> grids(ng);
  for (std::size_t g = 0; g < ng; ++g) grids[g] = in.grids()[g].base();
  std::vector<std::vector<RawHit>> hits(items.size());
  std::vector<std::size_t> stumpCount(items.size(), 0);
  auto runItem = [&](std::size_t i, WindowList& l) {
    const Item& it = items[i];
    scanTile(plans[it.cascade][it.scale], grids.data(), ng, it.x0, it.x1, it.y0, it.y1, static_cast<int>(it.scale), l,
             hits[i], stumpCount[i]);
  };
  if (params.threads == 1) {
    WindowList l;
    for (std::size_t i = 0; i < items.size(); ++i) runItem(i, l);
  } else {
    onThreads(params.threads, [&] {
      parallelFor(tbb::blocked_range<std::size_t>(0, items.size()), [&](const tbb::blocked_range<std::size_t>& r) {
        WindowList l;
        for (std::size_t i = r.begin(); i != r.end(); ++i) runItem(i, l);
      });
    });
  }
  std::vector<std::vector<RawHit>> out(nc);
  for (std::size_t i = 0; i < items.size(); ++i)
    out[items[i].cascade].insert(out[items[i].cascade].end(), hits[i].begin(), hits[i].end());
  for (auto& o : out)
    std::sort(o.begin(), o.end(), [](const RawHit& a, const RawHit& b) {
      return std::tie(a.scale, a.box.y, a.box.x) < std::tie(b.scale, b.box.y, b.box.x);
    });
  if (stats) {
    stats->assign(nc, ScanStats{});
    for (std::size_t c = 0; c < nc; ++c) {
      (*stats)[c].scales = plans[c].size();
      for (const GridScale& sp : plans[c]) (*stats)[c].windows += sp.win.xs.size() * sp.win.ys.size();
    }
    for (std::size_t i = 0; i < items.size(); ++i) (*stats)[items[i].cascade].stumps += stumpCount[i];
  }
  return out;
}

}  // namespace fusedet::boosting
