#include "fusedet/boost/aspect_cascades.h"

#include <algorithm>
#include <numeric>
#include <stdexcept>
#include <tuple>

namespace fusedet::boosting {

std::vector<const Cascade*> cascadesOf(const Cascade& model) {
  std::vector<const Cascade*> out{&model};
  for (const Cascade& a : model.aspectCascades) out.push_back(&a);
  return out;
}

MergedDetections mergeCascadeDetections(const std::vector<std::vector<Detection>>& perCascade, double mergeIou,
                                        GroupParams::AspectMerge mergeOrder) {
  struct Ref {
    std::size_t cascade, index;
  };
  std::vector<Ref> order;
  for (std::size_t k = 0; k < perCascade.size(); ++k)
    for (std::size_t d = 0; d < perCascade[k].size(); ++d) order.push_back({k, d});
  const bool cascadeFirst = mergeOrder == GroupParams::AspectMerge::kFirstCascadeFirst;
  std::stable_sort(order.begin(), order.end(), [&](const Ref& a, const Ref& b) {
    if (cascadeFirst && a.cascade != b.cascade) return a.cascade < b.cascade;
    return perCascade[a.cascade][a.index].score > perCascade[b.cascade][b.index].score;
  });
  // Pass 1 by score: who survives, and who suppressed whom.
  std::vector<std::vector<int>> suppressor(perCascade.size());  // -1 = kept, else order position
  std::vector<std::vector<Ref>> by(perCascade.size());
  for (std::size_t k = 0; k < perCascade.size(); ++k) suppressor[k].assign(perCascade[k].size(), -1);
  std::vector<Ref> keptSoFar;
  for (const Ref& r : order) {
    const Box& box = perCascade[r.cascade][r.index].box;
    for (const Ref& q : keptSoFar)
      if (q.cascade != r.cascade && iou(box, perCascade[q.cascade][q.index].box) > mergeIou) {
        suppressor[r.cascade][r.index] = static_cast<int>(&q - keptSoFar.data());
        break;
      }
    if (suppressor[r.cascade][r.index] < 0) keptSoFar.push_back(r);
  }
  // Pass 2 in cascade order: the output, and every detection's index in it.
  MergedDetections out;
  out.kept.resize(perCascade.size());
  std::vector<std::vector<int>> outIndex(perCascade.size());
  for (std::size_t k = 0; k < perCascade.size(); ++k) {
    outIndex[k].assign(perCascade[k].size(), -1);
    for (std::size_t d = 0; d < perCascade[k].size(); ++d)
      if (suppressor[k][d] < 0) {
        outIndex[k][d] = static_cast<int>(out.detections.size());
        out.detections.push_back(perCascade[k][d]);
      }
  }
  for (std::size_t k = 0; k < perCascade.size(); ++k) {
    out.kept[k].resize(perCascade[k].size());
    for (std::size_t d = 0; d < perCascade[k].size(); ++d) {
      const int s = suppressor[k][d];
      const Ref& q = s < 0 ? Ref{k, d} : keptSoFar[static_cast<std::size_t>(s)];
      out.kept[k][d] = outIndex[q.cascade][q.index];
    }
  }
  return out;
}

std::vector<Detection> groupModelHits(const Cascade& model, const std::vector<std::vector<RawHit>>& hits,
                                      const GroupParams& group, const LayerStack& stack,
                                      std::vector<std::vector<HitFate>>* fates) {
  const std::vector<const Cascade*> cascades = cascadesOf(model);
  if (hits.size() != cascades.size())
    throw std::invalid_argument("groupModelHits: " + std::to_string(hits.size()) + " hit lists for " +
                                std::to_string(cascades.size()) + " cascades");
  std::vector<std::vector<HitFate>> local(cascades.size());
  std::vector<std::vector<HitFate>>& f = fates ? *fates : local;
  f.assign(cascades.size(), {});
  std::vector<std::vector<Detection>> perCascade;
  for (std::size_t k = 0; k < cascades.size(); ++k)
    perCascade.push_back(groupHits(hits[k], group, model.className, stack, &f[k]));
  if (perCascade.size() == 1) return std::move(perCascade.front());
  MergedDetections merged = mergeCascadeDetections(perCascade, group.aspectMergeIou, group.aspectMerge);
  for (std::size_t k = 0; k < f.size(); ++k)
    for (HitFate& h : f[k])
      if (h.detection >= 0) h.detection = merged.kept[k][static_cast<std::size_t>(h.detection)];
  return std::move(merged.detections);
}

std::vector<std::vector<RawHit>> scanModel(const Detector& detector, const LayerStack& stack, const ScanParams& scan,
                                           ScanStats* stats) {
  std::vector<std::vector<RawHit>> out{detector.scan(stack, scan, stats)};
  for (const Cascade& a : detector.cascade().aspectCascades) {
    ScanStats s;
    out.push_back(Detector(a).scan(stack, scan, &s));
    if (stats) {
      stats->windows += s.windows;
      stats->stumps += s.stumps;
      stats->scales += s.scales;
    }
  }
  return out;
}

}  // namespace fusedet::boosting
