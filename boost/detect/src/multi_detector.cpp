// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/multi_detector.h"

#include "fusedet/boost/class_detection.h"

#include "fusedet/boost/integral_grids.h"
#include "opencv_pyramid.h"
#include "fusedet/boost/window_scanner.h"

namespace fusedet::boosting {

MultiDetector::MultiDetector(std::vector<Cascade> cascades) : cascades_(std::move(cascades)) {
  for (const Cascade& c : cascades_) c.validate();
}

std::vector<std::vector<RawHit>> MultiDetector::scan(const LayerStack& stack, const ScanParams& params,
                                                     std::vector<ScanStats>* stats) const {
  std::vector<const Cascade*> ours;
  std::vector<std::size_t> ourIndex;
  std::vector<LayerRequest> requests;
  for (std::size_t i = 0; i < cascades_.size(); ++i) {
    if (cascades_[i].isOpenCv()) continue;
    requireStackNetwork(cascades_[i], stack);
    ours.push_back(&cascades_[i]);
    ourIndex.push_back(i);
    for (LayerRequest& r : layerRequests(cascades_[i])) requests.push_back(std::move(r));
  }
  std::vector<std::vector<RawHit>> out(cascades_.size());
  std::vector<ScanStats> st(cascades_.size());
  if (!ours.empty()) {
    const IntegralGrids grids(stack, requests, params.threads);
    std::vector<ScanStats> ourStats;
    std::vector<std::vector<RawHit>> hits = scanCascades(ours, grids, params, &ourStats);
    for (std::size_t k = 0; k < ours.size(); ++k) {
      out[ourIndex[k]] = std::move(hits[k]);
      st[ourIndex[k]] = ourStats[k];
    }
  }
  for (std::size_t i = 0; i < cascades_.size(); ++i)
    if (cascades_[i].isOpenCv()) out[i] = scanOpenCvPyramid(cascades_[i], stack, params, &st[i]);
  if (stats) *stats = std::move(st);
  return out;
}

void MultiDetector::prepare(const LayerStack& stack, const ScanParams& params) const {
  std::vector<LayerRequest> requests;
  for (const Cascade& c : cascades_) {
    if (c.isOpenCv() || (usesNetworkLayers(c.layers) && stack.network.empty())) continue;
    for (LayerRequest& r : layerRequests(c)) requests.push_back(std::move(r));
  }
  if (!requests.empty()) (void)IntegralGrids(stack, requests, params.threads);
}

std::vector<Detection> detect(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                              const GroupParams& group) {
  // Every class with the same grouping and no laser extent: detectPerClass() with no class of its own.
  LaserExtentParams noExtent;
  noExtent.enabled = false;
  return detectPerClass(detector, stack, scan, group, noExtent, {});
}

}  // namespace fusedet::boosting
