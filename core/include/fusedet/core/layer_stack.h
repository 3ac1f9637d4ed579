// SPDX-License-Identifier: Apache-2.0
#pragma once
// LayerStack: named, registered 2D sensor layers of one scene (paper §3.1). Each layer keeps its
// own resolution; all are addressed in unit-square coordinates (x / w_l, y / h_l, paper eq. 1),
// so a feature or a box means the same place in every layer. Boxes and labels are given in the
// stack's reference pixel grid (width x height, the camera image).

#include <cstdint>
#include <opencv2/core/mat.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "fusedet/core/box.h"
#include "fusedet/core/network_record.h"
#include "fusedet/core/stamp.h"

namespace fusedet {

// Canonical layer names (paper Fig. 3). `hue_distance` is derived per class from `hue`.
namespace layer {
inline constexpr std::string_view kRed = "red";
inline constexpr std::string_view kGreen = "green";
inline constexpr std::string_view kBlue = "blue";
inline constexpr std::string_view kIntensity = "intensity";
inline constexpr std::string_view kHue = "hue";  // degrees [0, 360), float
inline constexpr std::string_view kHueDistance = "hue_distance";  // degrees [0, 180], float
inline constexpr std::string_view kDistance = "distance";  // metres, float, 0 where invalid
inline constexpr std::string_view kRemission = "remission";  // [0, 1], float
}  // namespace layer

struct Layer {
  std::string name;
  cv::Mat data;   // one channel: CV_8U, CV_16U or CV_32F
  cv::Mat valid;  // CV_8U, non-zero where data is measured; empty = every pixel valid

  int width() const { return data.cols; }
  int height() const { return data.rows; }
  bool hasMask() const { return !valid.empty(); }
};

class LayerStack {
 public:
  LayerStack() = default;
  LayerStack(int width, int height) : width_(width), height_(height) {}

  // Adds or replaces a layer. Throws std::invalid_argument for an empty name, a multi-channel or
  // unsupported depth, or a mask whose size differs from the data.
  void set(Layer layer);
  const Layer* find(std::string_view name) const;
  Layer* find(std::string_view name);
  // Like find() but throws std::out_of_range naming the missing layer and the ones present.
  const Layer& at(std::string_view name) const;
  bool has(std::string_view name) const { return find(name) != nullptr; }
  std::vector<std::string> names() const;
  std::span<const Layer> layers() const { return layers_; }
  std::size_t size() const { return layers_.size(); }

  // Reference pixel grid (camera image) that boxes and labels are expressed in.
  int width() const { return width_; }
  int height() const { return height_; }
  void setReferenceSize(int width, int height) { width_ = width; height_ = height; }

  // Unit-square <-> reference pixels.
  Box toUnit(const Box& pixels) const;
  Box toPixels(const Box& unit) const;
  // A unit-square box in the pixel grid of one layer (may be fractional).
  static Box toLayerPixels(const Layer& layer, const Box& unit);

  std::uint64_t id = 0;  // sequence number of the stack in its stream or data set
  Stamp stamp;           // time of the camera frame the stack was built from
  std::string source;    // where it came from, e.g. "kitti/000042" or "live"
  NetworkRecord network;  // the network that made its neural_* layers (empty: none)

 private:
  std::vector<Layer> layers_;
  int width_ = 0, height_ = 0;
};

}  // namespace fusedet
