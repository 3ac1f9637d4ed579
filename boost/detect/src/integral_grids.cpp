// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/integral_grids.h"
#include "fusedet/boost/parallel_for.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <bit>
#include <cstdint>
#include <cstring>
#include <stdexcept>

#include <sys/mman.h>

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "fusedet/core/hue_distance.h"

namespace fusedet::boosting {

namespace {

// One source layer feeding one slot: its pixels, or hue to be turned into hue_distance per row.
struct Source {
  cv::Mat data;
  std::optional<double> hueReference;  // set: data is hue (CV_32F), the slot is hue_distance
  cv::Mat hueValid;                     // the hue layer's mask (empty = every pixel has a hue)
};

// |v| as an unsigned integer that orders like it: the bits of a float or double without its sign
// (every NaN above +inf), an integer's value. Kept with integer maxima, which compile without
// branches, beside the integration's own dependency chain.
inline std::uint32_t magnitudeKey(float v) { return std::bit_cast<std::uint32_t>(v) & 0x7fffffffu; }
inline std::uint64_t magnitudeKey(double v) { return std::bit_cast<std::uint64_t>(v) & 0x7fffffffffffffffull; }
inline std::uint32_t magnitudeKey(std::uint8_t v) { return v; }
inline std::uint32_t magnitudeKey(std::uint16_t v) { return v; }
inline double magnitude(std::uint32_t key, float) { return std::bit_cast<float>(key); }
inline double magnitude(std::uint64_t key, double) { return std::bit_cast<double>(key); }
template <class T>
inline double magnitude(std::uint32_t key, T) { return key; }

// Integral rows of one slot, the recurrence of integrateLayer(): per row rowSum += v; cur = prev +
// rowSum; kRows rows at a time (their rowSum chains are independent: the additions of one row no
// longer wait for each other's latency; each value is the same sum as row by row). rowAt(y, k)
// gives the layer's row y (k: which of the kRows rows, for a caller that derives them). With
// kBound, `most` keeps the largest magnitudeKey() of the values.
template <int kRows, bool kBound, class T, class Acc, class Key, class RowAt>
void integrateRows(int y0, int w, const RowAt& rowAt, Acc* slot0, std::ptrdiff_t pitch, Key& most) {
  const T* in[kRows];
  Acc* cur[kRows];
  Acc rowSum[kRows];
  for (int k = 0; k < kRows; ++k) {
    in[k] = rowAt(y0 + k, k);
    cur[k] = slot0 + (y0 + 1 + k) * pitch;
    rowSum[k] = 0;
  }
  const Acc* prev = slot0 + y0 * pitch;
  for (int x = 0; x < w; ++x) {
    Acc above = prev[x + 1];
    for (int k = 0; k < kRows; ++k) {
      const T v = in[k][x];
      rowSum[k] += static_cast<Acc>(v);
      above = above + rowSum[k];
      cur[k][x + 1] = above;
      if constexpr (kBound) most = std::max(most, magnitudeKey(v));
    }
  }
}

// Every row of one slot (see integrateRows); returns the largest |value| (IntegralGrid::bounds)
// with kBound, else 0.
template <bool kBound, class T, class Acc, class RowAt>
double integrateRowsOf(int w, int h, const RowAt& rowAt, Acc* slot0, std::ptrdiff_t pitch) {
  constexpr int kRows = 4;
  decltype(magnitudeKey(T{})) most = 0;
  int y = 0;
  for (; y + kRows <= h; y += kRows) integrateRows<kRows, kBound, T>(y, w, rowAt, slot0, pitch, most);
  for (; y < h; ++y) integrateRows<1, kBound, T>(y, w, rowAt, slot0, pitch, most);
  return magnitude(most, T{});
}

template <bool kBound, class T, class Acc>
double integrateSlot(const cv::Mat& data, Acc* slot0, std::ptrdiff_t pitch) {
  return integrateRowsOf<kBound, T>(
      data.cols, data.rows, [&](int y, int) { return data.ptr<T>(y); }, slot0, pitch);
}

// An 8-bit layer into an int32 table (IntegralGrid::exactInt): integrateRows()'s recurrence, on
// x86 four columns per step - each step's row sums as a prefix sum of four values (integer sums
// are exact in any order, and fitsInt32() keeps every one below 2^31, so the table holds the same
// values), then the row above added (SSE2, part of every x86-64 CPU). Elsewhere integrateRows().
void integrateBytes(const cv::Mat& data, std::int32_t* slot0, std::ptrdiff_t pitch) {
#if defined(__SSE2__)
  const __m128i zero = _mm_setzero_si128();
  const int w = data.cols;
  for (int y = 0; y < data.rows; ++y) {
    const std::uint8_t* in = data.ptr<std::uint8_t>(y);
    const std::int32_t* prev = slot0 + y * pitch + 1;
    std::int32_t* cur = slot0 + (y + 1) * pitch + 1;
    __m128i rowSum = zero;  // the row's sum so far, in every lane
    int x = 0;
    for (; x + 4 <= w; x += 4) {
      std::int32_t four;
      std::memcpy(&four, in + x, sizeof four);
      __m128i v = _mm_unpacklo_epi16(_mm_unpacklo_epi8(_mm_cvtsi32_si128(four), zero), zero);
      v = _mm_add_epi32(v, _mm_slli_si128(v, 4));
      v = _mm_add_epi32(v, _mm_slli_si128(v, 8));
      v = _mm_add_epi32(v, rowSum);
      rowSum = _mm_shuffle_epi32(v, 0xFF);
      v = _mm_add_epi32(v, _mm_loadu_si128(reinterpret_cast<const __m128i*>(prev + x)));
      _mm_storeu_si128(reinterpret_cast<__m128i*>(cur + x), v);
    }
    std::int32_t sum = _mm_cvtsi128_si32(rowSum);
    for (; x < w; ++x) {
      sum += in[x];
      cur[x] = prev[x] + sum;
    }
  }
#else
  integrateSlot<false, std::uint8_t>(data, slot0, pitch);
#endif
}

double integrateHueDistance(const cv::Mat& hue, const cv::Mat& valid, double reference, double* slot0,
                            std::ptrdiff_t pitch) {
  const int w = hue.cols;
  std::vector<float> dist(static_cast<std::size_t>(w) * 4);
  auto rowAt = [&](int y, int k) {
    float* out = dist.data() + static_cast<std::size_t>(k) * static_cast<std::size_t>(w);
    hueDistanceRow(hue.ptr<float>(y), valid.empty() ? nullptr : valid.ptr<unsigned char>(y), out, w, reference);
    return static_cast<const float*>(out);
  };
  return integrateRowsOf<true, float>(w, hue.rows, rowAt, slot0, pitch);
}

// int32 tables are exact for 8-bit layers up to this many pixels (255 * pixels < 2^31).
bool fitsInt32(const cv::Mat& data) {
  return data.depth() == CV_8U && double(data.cols) * double(data.rows) * 255.0 < 2147483647.0;
}

double integrateSource(const Source& s, double* slot0, std::ptrdiff_t pitch) {
  if (s.hueReference) return integrateHueDistance(s.data, s.hueValid, *s.hueReference, slot0, pitch);
  switch (s.data.depth()) {
    case CV_8U: return integrateSlot<true, std::uint8_t>(s.data, slot0, pitch);
    case CV_16U: return integrateSlot<true, std::uint16_t>(s.data, slot0, pitch);
    case CV_32F: return integrateSlot<true, float>(s.data, slot0, pitch);
    case CV_64F: return integrateSlot<true, double>(s.data, slot0, pitch);
    default: throw std::invalid_argument("IntegralGrids: layer depth must be 8U, 16U, 32F or 64F");
  }
}

// Tables of a camera-size stack take tens of MB and are needed again for the next stack: fresh
// memory would cost page faults and zeroing every time, so each thread keeps the buffers of its
// last grids (a few, released at thread exit).
thread_local std::vector<std::vector<double>> tBuffers;
thread_local std::vector<std::vector<std::int32_t>> tIntBuffers;

// Asks the kernel for transparent huge pages (2 MiB) over the whole 2 MiB pages of [p, p + bytes):
// the scanners read tables of tens of MB at scattered rows, and with 4 KiB pages nearly every
// corner of a later stage is another page (TLB misses; measured: bench/README.md). Where the kernel
// gives none (THP "never", another page size), nothing changes.
void adviseHugePages(const void* p, std::size_t bytes) {
  constexpr std::uintptr_t kHuge = std::uintptr_t(2) << 20;
  const auto start = reinterpret_cast<std::uintptr_t>(p);
  const std::uintptr_t from = (start + kHuge - 1) & ~(kHuge - 1), to = (start + bytes) & ~(kHuge - 1);
  if (to > from) (void)madvise(reinterpret_cast<void*>(from), to - from, MADV_HUGEPAGE);
}

// The pooled buffer of n values if there is one (the next stack has the same sizes), else the
// last: a buffer of another grid's size would be grown by resize(), which zeroes what it adds -
// megabytes per stack when a camera-size grid took the laser grid's buffer.
template <class T>
std::vector<T> takeBuffer(std::vector<std::vector<T>>& pool, std::size_t n) {
  std::vector<T> b;
  if (!pool.empty()) {
    auto it = std::find_if(pool.begin(), pool.end(), [&](const std::vector<T>& p) { return p.size() == n; });
    if (it == pool.end()) it = pool.end() - 1;
    b = std::move(*it);
    pool.erase(it);
  }
  if (b.capacity() < n) {  // a new buffer: huge pages asked for before its first touch
    b = std::vector<T>();
    b.reserve(n);
    adviseHugePages(b.data(), n * sizeof(T));
  }
  b.resize(n);
  return b;
}

// Zeroes what the integration does not write: row 0, column 0 of every slot's rows, the padding.
template <class T>
void prepare(std::vector<T>& d, const IntegralGrid& g, std::size_t n) {
  std::fill(d.begin(), d.begin() + g.pitch, T(0));
  for (std::size_t i = static_cast<std::size_t>(g.pitch); i < n; i += static_cast<std::size_t>(g.stride)) d[i] = T(0);
  std::fill(d.begin() + static_cast<std::ptrdiff_t>(n), d.end(), T(0));
}

}  // namespace

IntegralGrids::~IntegralGrids() {
  for (IntegralGrid& g : grids_) {
    if (tBuffers.size() < 4 && !g.data.empty()) tBuffers.push_back(std::move(g.data));
    if (tIntBuffers.size() < 4 && !g.idata.empty()) tIntBuffers.push_back(std::move(g.idata));
  }
}

IntegralGrids::IntegralGrids(const LayerStack& stack, const std::vector<LayerRequest>& requests, int threads)
    : refWidth_(stack.width()), refHeight_(stack.height()) {
  if (refWidth_ <= 0 || refHeight_ <= 0) throw std::invalid_argument("IntegralGrids: stack has no reference size");
  // Resolve every distinct request to its source (IntegralStack's rules) and group by pixel grid.
  struct Job {
    Source source;
    SlotRef ref;
  };
  std::vector<Job> jobs;
  stackHasHueDistance_ = stack.has(layer::kHueDistance);
  for (const LayerRequest& asked : requests) {
    const LayerRequest r = normalized(asked);
    if (std::any_of(index_.begin(), index_.end(), [&](const auto& e) { return e.first == r; })) continue;
    Source src;
    const Layer* l = stack.find(r.name);
    if (!l && r.name == layer::kHueDistance && stack.has(layer::kHue)) {
      if (!r.referenceHue) throw std::invalid_argument("IntegralGrids: layer 'hue_distance' needs a reference hue");
      src.data = stack.at(layer::kHue).data;
      if (src.data.type() != CV_32FC1) src.data.convertTo(src.data, CV_32F);
      src.hueReference = r.referenceHue;
      src.hueValid = stack.at(layer::kHue).valid;
    } else {
      if (!l) stack.at(r.name);  // throws, naming the missing layer and the ones present
      if (l->data.channels() != 1 || l->data.empty())
        throw std::invalid_argument("IntegralGrids: layer '" + r.name + "' must be a non-empty single-channel image");
      src.data = l->data;
    }
    const int w = src.data.cols, h = src.data.rows;
    const bool exactInt = !src.hueReference && fitsInt32(src.data);
    auto g = std::find_if(grids_.begin(), grids_.end(),
                          [&](const IntegralGrid& x) { return x.width == w && x.height == h && x.exactInt == exactInt; });
    if (g == grids_.end()) {
      grids_.push_back(IntegralGrid{});
      g = grids_.end() - 1;
      g->width = w;
      g->height = h;
      g->exactInt = exactInt;
      g->stride = w + 1;
    }
    const SlotRef ref{static_cast<int>(g - grids_.begin()), static_cast<int>(g->slots.size())};
    g->slots.push_back(r);
    index_.emplace_back(r, ref);
    jobs.push_back(Job{src, ref});
  }
  for (IntegralGrid& g : grids_) {
    g.pitch = g.stride * static_cast<std::ptrdiff_t>(g.slots.size());
    g.bounds.assign(g.slots.size(), 0.0);
    const std::size_t n = static_cast<std::size_t>(g.pitch) * static_cast<std::size_t>(g.height + 1);
    if (g.exactInt) {
      g.idata = takeBuffer(tIntBuffers, n + kGridPad);
      prepare(g.idata, g, n);
    } else {
      g.data = takeBuffer(tBuffers, n + kGridPad);
      prepare(g.data, g, n);
    }
  }
  auto run = [&](std::size_t i) {
    const Job& j = jobs[i];
    IntegralGrid& g = grids_[static_cast<std::size_t>(j.ref.grid)];
    double& bound = g.bounds[static_cast<std::size_t>(j.ref.slot)];
    if (g.exactInt) {
      integrateBytes(j.source.data, g.idata.data() + j.ref.slot * g.stride, g.pitch);
      bound = 255;  // 8-bit values
    } else {
      bound = integrateSource(j.source, g.data.data() + j.ref.slot * g.stride, g.pitch);
    }
  };
  if (threads == 1 || jobs.size() < 2) {
    for (std::size_t i = 0; i < jobs.size(); ++i) run(i);
    return;
  }
  // Largest jobs first, one task each (hue_distance slots derive their values too; double tables
  // write twice the bytes), so that no big slot is left alone at the end while the other thread
  // idles. Each slot is written by one job, so the order changes no value.
  auto cost = [&](std::size_t i) {
    const Source& src = jobs[i].source;
    const double pixels = double(src.data.cols) * double(src.data.rows);
    const bool exactInt = grids_[static_cast<std::size_t>(jobs[i].ref.grid)].exactInt;
    return pixels * (exactInt ? 1.0 : 2.0) * (src.hueReference ? 2.0 : 1.0);
  };
  std::vector<std::size_t> order(jobs.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return cost(a) > cost(b); });
  auto all = [&] {
    parallelForEach(
        std::size_t(0), order.size(), [&](std::size_t k) { run(order[k]); }, tbb::simple_partitioner());
  };
  if (threads > 1) {
    tbb::task_arena arena(std::min(threads, tbb::info::default_concurrency()));
    arena.execute(all);
  } else {
    all();
  }
}

LayerRequest IntegralGrids::normalized(const LayerRequest& r) const {
  if (r.name == layer::kHueDistance && !stackHasHueDistance_) return r;
  return LayerRequest{r.name, std::nullopt};
}

SlotRef IntegralGrids::find(const LayerRequest& request) const {
  const LayerRequest key = normalized(request);
  for (const auto& [r, ref] : index_)
    if (r == key) return ref;
  throw std::logic_error("IntegralGrids: layer '" + request.name + "' was not requested");
}

}  // namespace fusedet::boosting
