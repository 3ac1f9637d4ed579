// SPDX-License-Identifier: Apache-2.0
#pragma once
// IntegralGrids: the summed-area tables of every layer that a set of models reads, built in one
// pass over a stack and shared by all of them (internal to boost/, used by window_scanner.h).
//
// Layers of the same pixel grid (the camera layers at image size, the laser layers at theirs) live
// in one buffer with their rows interleaved: integral row y of slot 0, of slot 1, ... then row
// y + 1. A window's features on different layers then read neighbouring memory, and a corner of a
// feature on slot s of a grid is one offset from the window's origin in that grid
// (y * pitch + s * stride + x), so a window needs one origin per grid, not one per layer.
//
// Values are those of integrateLayer() (integral_stack.h), bit for bit: double sums in the same
// order. 8-bit layers whose whole sum stays below 2^31 get int32 tables instead (exact integers
// either way, so every rectangle sum converts to the same double), half the memory to stream.
// `hue_distance` is derived per reference hue (each class may have its own); a stack that carries
// its own hue_distance layer is used as is, as IntegralStack does.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

// A layer a model reads: its name and, for hue_distance, the model's reference hue.
struct LayerRequest {
  std::string name;
  std::optional<double> referenceHue;
  bool operator==(const LayerRequest&) const = default;
};

struct IntegralGrid {
  int width = 0, height = 0;       // the layers' own pixel grid
  bool exactInt = false;           // int32 tables in `idata` (8-bit layers), else double in `data`
  std::ptrdiff_t stride = 0;       // width + 1: one layer's integral row
  std::ptrdiff_t pitch = 0;        // slots * stride: one integral row of every slot
  std::vector<LayerRequest> slots;
  // Per slot: the largest |value| of its layer (NaN if a value is NaN), which bounds its rectangle
  // sums for the scanner's quick decisions.
  std::vector<double> bounds;
  std::vector<double> data;        // (height + 1) * pitch values, then padding for vector reads
  std::vector<std::int32_t> idata;  // the same layout when exactInt
  const void* base() const { return exactInt ? static_cast<const void*>(idata.data()) : data.data(); }
};

// Where one requested layer lives.
struct SlotRef {
  int grid = 0, slot = 0;
};

class IntegralGrids {
 public:
  // Integrates the distinct `requests` of `stack` (threads: 1 = the calling thread, 0 = all
  // cores). Throws std::out_of_range naming a missing layer (and the ones present),
  // std::invalid_argument for hue_distance without a reference hue or a stack without a size.
  IntegralGrids(const LayerStack& stack, const std::vector<LayerRequest>& requests, int threads);
  ~IntegralGrids();  // hands the tables' buffers to the thread's next IntegralGrids
  IntegralGrids(const IntegralGrids&) = delete;
  IntegralGrids& operator=(const IntegralGrids&) = delete;

  int refWidth() const { return refWidth_; }
  int refHeight() const { return refHeight_; }
  const std::vector<IntegralGrid>& grids() const { return grids_; }
  SlotRef find(const LayerRequest& request) const;  // must have been requested

 private:
  // The reference hue only tells hue_distance layers apart that are derived here.
  LayerRequest normalized(const LayerRequest& r) const;

  bool stackHasHueDistance_ = false;
  int refWidth_ = 0, refHeight_ = 0;
  std::vector<IntegralGrid> grids_;
  std::vector<std::pair<LayerRequest, SlotRef>> index_;
};

// Extra doubles behind each grid's table: vector loads of a few lanes past the last window stay
// inside the allocation.
inline constexpr std::size_t kGridPad = 16;

}  // namespace fusedet::boosting
