#include "fusedet/boost/multi_detector.h"

#include "fusedet/boost/aspect_cascades.h"
#include "fusedet/boost/class_detection.h"

#include "integral_grids.h"
#include "opencv_pyramid.h"
#include "window_scanner.h"

namespace fusedet::boosting {

MultiDetector::MultiDetector(std::vector<Cascade> cascades) : cascades_(std::move(cascades)) {
  for (const Cascade& c : cascades_) c.validate();
}

std::vector<std::vector<RawHit>> MultiDetector::scan(const LayerStack& stack, const ScanParams& params,
                                                     std::vector<ScanStats>* stats) const {
  std::vector<std::vector<std::vector<RawHit>>> all = scanModels(stack, params, stats);
  std::vector<std::vector<RawHit>> out;
  for (auto& model : all) out.push_back(std::move(model.front()));
  return out;
}

std::vector<std::vector<std::vector<RawHit>>> MultiDetector::scanModels(const LayerStack& stack,
                                                                        const ScanParams& params,
                                                                        std::vector<ScanStats>* stats) const {
  // Every cascade of our models (aspect cascades included) in one pass; (model, cascade) of each.
  std::vector<const Cascade*> ours;
  std::vector<std::pair<std::size_t, std::size_t>> ourIndex;
  std::vector<LayerRequest> requests;
  std::vector<std::vector<std::vector<RawHit>>> out(cascades_.size());
  for (std::size_t i = 0; i < cascades_.size(); ++i) {
    const std::vector<const Cascade*> parts = cascadesOf(cascades_[i]);
    out[i].resize(parts.size());
    if (cascades_[i].isOpenCv()) continue;
    for (std::size_t k = 0; k < parts.size(); ++k) {
      ours.push_back(parts[k]);
      ourIndex.emplace_back(i, k);
      for (LayerRequest& r : layerRequests(*parts[k])) requests.push_back(std::move(r));
    }
  }
  std::vector<ScanStats> st(cascades_.size());
  if (!ours.empty()) {
    const IntegralGrids grids(stack, requests, params.threads);
    std::vector<ScanStats> ourStats;
    std::vector<std::vector<RawHit>> hits = scanCascades(ours, grids, params, &ourStats);
    for (std::size_t k = 0; k < ours.size(); ++k) {
      const auto [i, part] = ourIndex[k];
      out[i][part] = std::move(hits[k]);
      st[i].windows += ourStats[k].windows;
      st[i].stumps += ourStats[k].stumps;
      st[i].scales += ourStats[k].scales;
    }
  }
  for (std::size_t i = 0; i < cascades_.size(); ++i)
    if (cascades_[i].isOpenCv()) out[i].front() = scanOpenCvPyramid(cascades_[i], stack, params, &st[i]);
  if (stats) *stats = std::move(st);
  return out;
}

std::vector<Detection> detect(const MultiDetector& detector, const LayerStack& stack, const ScanParams& scan,
                              const GroupParams& group) {
  // Every class with the same grouping and no laser extent: detectPerClass() with no class of its own.
  LaserExtentParams noExtent;
  noExtent.enabled = false;
  return detectPerClass(detector, stack, scan, group, noExtent, {});
}

}  // namespace fusedet::boosting
