// SPDX-License-Identifier: Apache-2.0
#pragma once
// StackDetector: the pipeline's one, narrow detection call - every configured class on one
// LayerStack. CascadeSet implements it with boosting::MultiDetector: all model files in one pass
// per stack (shared integrals; each model's hue_distance from its own reference hue).

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/laser_extent.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"
#include "fusedet/daemon/config.h"
#include "fusedet/fusion/fuser.h"

namespace fusedet::daemon {

class StackDetector {
 public:
  virtual ~StackDetector() = default;
  // Detections of every class, boxes in the stack's reference pixels. Called from one thread.
  virtual std::vector<Detection> detect(const LayerStack& stack) const = 0;
  // Class names, in model order.
  virtual std::vector<std::string> classes() const = 0;
  // The classes whose models read the network's layers (neural_*, config section neural).
  virtual std::vector<std::string> networkClasses() const { return {}; }
  // Detections of every class not in networkClasses(), for a stack the network failed on (it
  // lacks the network's layers). Same boxes, scores and order as detect() gives those classes.
  virtual std::vector<Detection> detectWithoutNetwork(const LayerStack& stack) const { return detect(stack); }
  // Readies the calling thread (and its helpers) for stacks of this one's sizes, e.g. buffers, so
  // that the first real stack costs what later ones do. Called from the detecting thread.
  virtual void prepare(const LayerStack& /*stack*/) const {}
};

// The config's detection section in the library's terms (one meaning for every key).
boosting::ScanParams scanParamsFrom(const Config::Detection& d);
boosting::GroupParams groupParamsFrom(const Config::Detection& d);
boosting::LaserExtentParams laserExtentFrom(const Config::Detection& d);
std::vector<boosting::ClassGrouping> classGroupingFrom(const Config::Detection& d);  // detection.classes

class CascadeSet : public StackDetector {
 public:
  // Loads every model file (relative paths against `base`); throws std::runtime_error naming the
  // file and the problem (missing, malformed, invalid cascade, two models of one class, a layer the
  // stacks will not have: `stackLayers` are the layers fusion makes, fusion::Fuser::layerNames(),
  // plus hue_distance when hue is among them; a model using neural layers must record `network`,
  // the network that makes the stacks' ones: fusedet/core/network_record.h requireSameNetwork).
  CascadeSet(const Config::Detection& settings, const std::filesystem::path& base = {},
             const std::vector<std::string>& stackLayers = fusion::Fuser::layerNames(),
             const NetworkRecord& network = {});

  std::vector<Detection> detect(const LayerStack& stack) const override;
  std::vector<std::string> classes() const override;
  std::vector<std::string> networkClasses() const override;
  std::vector<Detection> detectWithoutNetwork(const LayerStack& stack) const override;
  void prepare(const LayerStack& stack) const override;  // the tables (MultiDetector::prepare)
  const std::vector<std::filesystem::path>& files() const { return files_; }
  // detection.classes entries that name no loaded model (a typo, or a class not deployed): they
  // change nothing, so the constructor logs a warning naming them and the loaded classes.
  std::vector<std::string> unmatchedClassSettings() const;

 private:
  std::unique_ptr<boosting::MultiDetector> detector_;
  // The models that do not read network layers (null when every model does), for
  // detectWithoutNetwork; the same Cascade objects' copies, in the same order.
  std::unique_ptr<boosting::MultiDetector> withoutNetwork_;
  std::vector<std::filesystem::path> files_;
  boosting::ScanParams scan_;
  boosting::GroupParams group_;
  boosting::LaserExtentParams extent_;  // detection.laser_extent
  std::vector<boosting::ClassGrouping> perClass_;  // detection.classes
};

}  // namespace fusedet::daemon
