// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/layer_stack.h"

#include <stdexcept>

namespace fusedet {

void LayerStack::set(Layer layer) {
  if (layer.name.empty()) throw std::invalid_argument("LayerStack::set: layer without a name");
  if (layer.data.channels() != 1)
    throw std::invalid_argument("LayerStack::set: layer '" + layer.name + "' has " +
                                std::to_string(layer.data.channels()) + " channels, expected 1");
  const int depth = layer.data.depth();
  if (depth != CV_8U && depth != CV_16U && depth != CV_32F)
    throw std::invalid_argument("LayerStack::set: layer '" + layer.name +
                                "' must be 8-bit, 16-bit or float");
  if (!layer.valid.empty() &&
      (layer.valid.size() != layer.data.size() || layer.valid.type() != CV_8UC1))
    throw std::invalid_argument("LayerStack::set: mask of layer '" + layer.name +
                                "' must be CV_8UC1 of the layer's size");
  if (Layer* existing = find(layer.name)) {
    *existing = std::move(layer);
  } else {
    layers_.push_back(std::move(layer));
  }
}

const Layer* LayerStack::find(std::string_view name) const {
  for (const Layer& l : layers_)
    if (l.name == name) return &l;
  return nullptr;
}

Layer* LayerStack::find(std::string_view name) {
  for (Layer& l : layers_)
    if (l.name == name) return &l;
  return nullptr;
}

const Layer& LayerStack::at(std::string_view name) const {
  if (const Layer* l = find(name)) return *l;
  std::string present;
  for (const Layer& l : layers_) present += (present.empty() ? "" : ", ") + l.name;
  throw std::out_of_range("layer '" + std::string(name) + "' not in stack (has: " +
                          (present.empty() ? "none" : present) + ")");
}

std::vector<std::string> LayerStack::names() const {
  std::vector<std::string> out;
  out.reserve(layers_.size());
  for (const Layer& l : layers_) out.push_back(l.name);
  return out;
}

Box LayerStack::toUnit(const Box& p) const {
  return Box{p.x / width_, p.y / height_, p.w / width_, p.h / height_};
}

Box LayerStack::toPixels(const Box& u) const {
  return Box{u.x * width_, u.y * height_, u.w * width_, u.h * height_};
}

Box LayerStack::toLayerPixels(const Layer& layer, const Box& u) {
  const double w = layer.width(), h = layer.height();
  return Box{u.x * w, u.y * h, u.w * w, u.h * h};
}

}  // namespace fusedet
