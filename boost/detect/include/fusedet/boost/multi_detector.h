// SPDX-License-Identifier: Apache-2.0
#pragma once
// MultiDetector: every class on one stack in one pass - what a robot runs on each stack.
//
// The summed-area tables are built once per stack for all models (only a model's hue_distance
// layer, derived with its own reference hue, is its own; models with the same reference hue share
// it), and the windows of all models, scales and positions are one pool of work for the threads.
// The decisions are those of each model's own Detector: scan(stack)[i] equals
// Detector(cascade(i)).scan(stack) hit for hit, score for score, in the same order, for any thread
// count (tested on real KITTI stacks). Imported OpenCV models are accepted too; they scan their
// own image pyramid (nothing to share) after our models.
//
//   boosting::MultiDetector all({loadModel("car.json"), loadModel("person.json"), loadModel("bike.json")});
//   std::vector<Detection> d = boosting::detect(all, stack, scan, group);   // class by class
//   // or: auto hits = all.scan(stack, scan);  hits[i] = raw hits of all.cascade(i)

#include <cstddef>
#include <vector>

#include "fusedet/boost/cascade.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::boosting {

class MultiDetector {
 public:
  // Validates every cascade (std::invalid_argument naming its source and the problem).
  explicit MultiDetector(std::vector<Cascade> cascades);

  std::size_t size() const { return cascades_.size(); }
  const Cascade& cascade(std::size_t i) const { return cascades_.at(i); }

  // Raw hits of each model (index = model order), each in (scale, row, column) order. stats
  // (optional) gets one ScanStats per model. Throws std::out_of_range naming a layer a model needs
  // that the stack lacks, std::invalid_argument for a scale factor <= 1.
  std::vector<std::vector<RawHit>> scan(const LayerStack& stack, const ScanParams& params,
                                        std::vector<ScanStats>* stats = nullptr) const;

  // Builds and drops the tables scan() builds for stacks of this one's sizes and layers, on
  // params.threads threads: each thread then holds its table buffers (integral_grids.h keeps the
  // last ones per thread), so the first real scan() does not pay for fresh memory (a service,
  // before its first stack). Models whose network layers the stack lacks are left out.
  void prepare(const LayerStack& stack, const ScanParams& params) const;

 private:
  std::vector<Cascade> cascades_;
};

// Scan + group for every model: the detections of model 0, then model 1, ... (each model's
// className on its detections; grouping.h's rules per model).
std::vector<Detection> detect(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                              const GroupParams& group);

}  // namespace fusedet::boosting
