// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/integral_grids.h"
#include "fusedet/boost/parallel_for.h"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <stdexcept>

#include "fusedet/core/hue_distance.h"

namespace fusedet::boosting {

namespace {

// One source layer feeding one slot: its pixels, or hue to be turned into hue_distance per row.
struct Source {
  cv::Mat data;
  std::optional<double> hueReference;  // set: data is hue (CV_32F), the slot is hue_distance
  cv::Mat hueValid;                     // the hue layer's mask (empty = every pixel has a hue)
};

// Integral rows of one slot, the recurrence of integrateLayer(): rowSum += v; cur = prev + rowSum.
template <class T, class Acc>
void integrateSlot(const cv::Mat& data, Acc* slot0, std::ptrdiff_t pitch) {
  const int w = data.cols, h = data.rows;
  for (int y = 0; y < h; ++y) {
    const T* row = data.ptr<T>(y);
    const Acc* prev = slot0 + y * pitch;
    Acc* cur = slot0 + (y + 1) * pitch;
    Acc rowSum = 0;
    for (int x = 0; x < w; ++x) {
      rowSum += static_cast<Acc>(row[x]);
      cur[x + 1] = prev[x + 1] + rowSum;
    }
  }
}

void integrateHueDistance(const cv::Mat& hue, const cv::Mat& valid, double reference, double* slot0,
                          std::ptrdiff_t pitch) {
  const int w = hue.cols, h = hue.rows;
  std::vector<float> dist(static_cast<std::size_t>(w));
  for (int y = 0; y < h; ++y) {
    hueDistanceRow(hue.ptr<float>(y), valid.empty() ? nullptr : valid.ptr<unsigned char>(y), dist.data(), w,
                   reference);
    const double* prev = slot0 + y * pitch;
    double* cur = slot0 + (y + 1) * pitch;
    double rowSum = 0;
    for (int x = 0; x < w; ++x) {
      rowSum += static_cast<double>(dist[static_cast<std::size_t>(x)]);
      cur[x + 1] = prev[x + 1] + rowSum;
    }
  }
}

// int32 tables are exact for 8-bit layers up to this many pixels (255 * pixels < 2^31).
bool fitsInt32(const cv::Mat& data) {
  return data.depth() == CV_8U && double(data.cols) * double(data.rows) * 255.0 < 2147483647.0;
}

void integrateSource(const Source& s, double* slot0, std::ptrdiff_t pitch) {
  if (s.hueReference) return integrateHueDistance(s.data, s.hueValid, *s.hueReference, slot0, pitch);
  switch (s.data.depth()) {
    case CV_8U: return integrateSlot<std::uint8_t>(s.data, slot0, pitch);
    case CV_16U: return integrateSlot<std::uint16_t>(s.data, slot0, pitch);
    case CV_32F: return integrateSlot<float>(s.data, slot0, pitch);
    case CV_64F: return integrateSlot<double>(s.data, slot0, pitch);
    default: throw std::invalid_argument("IntegralGrids: layer depth must be 8U, 16U, 32F or 64F");
  }
}

// Tables of a camera-size stack take tens of MB and are needed again for the next stack: fresh
// memory would cost page faults and zeroing every time, so each thread keeps the buffers of its
// last grids (a few, released at thread exit).
thread_local std::vector<std::vector<double>> tBuffers;
thread_local std::vector<std::vector<std::int32_t>> tIntBuffers;

template <class T>
std::vector<T> takeBuffer(std::vector<std::vector<T>>& pool, std::size_t n) {
  std::vector<T> b;
  if (!pool.empty()) {
    b = std::move(pool.back());
    pool.pop_back();
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
    if (g.exactInt)
      integrateSlot<std::uint8_t>(j.source.data, g.idata.data() + j.ref.slot * g.stride, g.pitch);
    else
      integrateSource(j.source, g.data.data() + j.ref.slot * g.stride, g.pitch);
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
