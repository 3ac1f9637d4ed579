// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/stack_detector.h"

#include <algorithm>
#include <set>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "fusedet/boost/model_io.h"

namespace fusedet::daemon {

boosting::ScanParams scanParamsFrom(const Config::Detection& d) {
  boosting::ScanParams p;
  p.scaleFactor = d.scaleFactor;
  p.minWidth = d.minSize[0];
  p.minHeight = d.minSize[1];
  p.maxWidth = d.maxSize[0];
  p.maxHeight = d.maxSize[1];
  p.step = d.step;
  p.threads = d.threads;
  return p;
}

boosting::GroupParams groupParamsFrom(const Config::Detection& d) {
  boosting::GroupParams g;
  g.minNeighbors = d.minNeighbors;
  return g;
}

boosting::LaserExtentParams laserExtentFrom(const Config::Detection& d) {
  boosting::LaserExtentParams p;
  p.enabled = d.laserExtent;
  return p;
}

std::vector<boosting::ClassGrouping> classGroupingFrom(const Config::Detection& d) {
  std::vector<boosting::ClassGrouping> out;
  for (const auto& k : d.classes) out.push_back({k.name, k.minNeighbors, k.laserExtent});
  return out;
}

namespace {

// A model trained on layers the daemon's stacks do not have would fail on every stack: refuse it
// when it is loaded (at start, or at reload, where the old models then keep serving).
void checkLayers(const boosting::Cascade& cascade, const std::filesystem::path& file, const std::vector<std::string>& stackLayers,
                 const NetworkRecord& network) {
  const auto made = [&](const std::string& name) {
    return std::find(stackLayers.begin(), stackLayers.end(), name) != stackLayers.end();
  };
  for (const std::string& name : cascade.layers) {
    if (made(name) || (name == layer::kHueDistance && made(std::string(layer::kHue)))) continue;
    std::string list;
    for (const std::string& l : stackLayers) list += (list.empty() ? "" : ", ") + l;
    if (made(std::string(layer::kHue))) list += ", hue_distance";
    throw std::runtime_error(file.string() + ": the model (class '" + cascade.className + "') uses layer '" + name +
                             "', which fusedetd's stacks do not have (" + list +
                             "); train it on those layers (fusedet train --layers)");
  }
  if (usesNetworkLayers(cascade.layers))
    requireSameNetwork(cascade.network, file.string() + " (class '" + cascade.className + "')", network,
                       "fusedetd's network (config section neural)");
}

}  // namespace

CascadeSet::CascadeSet(const Config::Detection& settings, const std::filesystem::path& base,
                       const std::vector<std::string>& stackLayers, const NetworkRecord& network)
    : scan_(scanParamsFrom(settings)),
      group_(groupParamsFrom(settings)),
      extent_(laserExtentFrom(settings)),
      perClass_(classGroupingFrom(settings)) {
  if (settings.models.empty()) throw std::runtime_error("detection.models: no model files configured");
  std::set<std::string> seen;
  std::vector<boosting::Cascade> cascades;
  for (const auto& m : settings.models) {
    std::filesystem::path file = m;
    if (file.is_relative() && !base.empty()) file = base / file;
    boosting::Cascade cascade = boosting::loadModel(file);
    checkLayers(cascade, file, stackLayers, network);
    if (!seen.insert(cascade.className).second)
      throw std::runtime_error(file.string() + ": a second model of class '" + cascade.className + "'");
    cascades.push_back(std::move(cascade));
    files_.push_back(file);
  }
  try {
    std::vector<boosting::Cascade> plain;
    for (const boosting::Cascade& c : cascades)
      if (!usesNetworkLayers(c.layers)) plain.push_back(c);
    if (plain.size() < cascades.size() && !plain.empty())
      withoutNetwork_ = std::make_unique<boosting::MultiDetector>(std::move(plain));
    detector_ = std::make_unique<boosting::MultiDetector>(std::move(cascades));
  } catch (const std::invalid_argument& e) {
    throw std::runtime_error(std::string("detection.models: ") + e.what());
  }
  for (const std::string& name : unmatchedClassSettings()) {
    std::string loaded;
    for (const std::string& c : classes()) loaded += (loaded.empty() ? "" : ", ") + c;
    spdlog::warn("detection.classes.{}: no model of class '{}' is loaded ({}); its settings are not used", name, name,
                 loaded);
  }
}

std::vector<std::string> CascadeSet::unmatchedClassSettings() const {
  const std::vector<std::string> loaded = classes();
  std::vector<std::string> out;
  for (const boosting::ClassGrouping& k : perClass_)
    if (std::find(loaded.begin(), loaded.end(), k.className) == loaded.end()) out.push_back(k.className);
  return out;
}

std::vector<Detection> CascadeSet::detect(const LayerStack& stack) const {
  return boosting::detectPerClass(*detector_, stack, scan_, group_, extent_, perClass_);
}

std::vector<Detection> CascadeSet::detectWithoutNetwork(const LayerStack& stack) const {
  if (networkClasses().empty()) return detect(stack);
  if (!withoutNetwork_) return {};
  return boosting::detectPerClass(*withoutNetwork_, stack, scan_, group_, extent_, perClass_);
}

void CascadeSet::prepare(const LayerStack& stack) const { detector_->prepare(stack, scan_); }

std::vector<std::string> CascadeSet::networkClasses() const {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < detector_->size(); ++i)
    if (usesNetworkLayers(detector_->cascade(i).layers)) names.push_back(detector_->cascade(i).className);
  return names;
}

std::vector<std::string> CascadeSet::classes() const {
  std::vector<std::string> names;
  for (std::size_t i = 0; i < detector_->size(); ++i) names.push_back(detector_->cascade(i).className);
  return names;
}

}  // namespace fusedet::daemon
