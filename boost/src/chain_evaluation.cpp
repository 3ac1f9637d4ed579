#include "fusedet/boost/chain_evaluation.h"

#include <chrono>
#include <numeric>
#include <stdexcept>

#include "fusedet/boost/integral_stack.h"

namespace fusedet::boosting {

void refineBoxes(std::vector<Detection>& detections, const std::vector<std::vector<RawHit>>& hits,
                 const std::vector<std::vector<HitFate>>& fates, const LayerStack& stack,
                 const LaserExtentParams& extent, const BoxRegression& regression, std::vector<GroupedBox>* groups) {
  if (!regression.fitted() && !groups) {
    refineToLaserExtent(detections, stack, extent);
    return;
  }
  std::vector<GroupedBox> g(detections.size());
  for (std::size_t i = 0; i < detections.size(); ++i) g[i].groupBox = detections[i].box;
  for (std::size_t k = 0; k < hits.size() && k < fates.size(); ++k)
    for (std::size_t i = 0; i < hits[k].size() && i < fates[k].size(); ++i) {
      const HitFate& f = fates[k][i];
      if (f.outcome == HitFate::Outcome::kKept && f.detection >= 0 && static_cast<std::size_t>(f.detection) < g.size())
      {
        g[static_cast<std::size_t>(f.detection)].members.push_back(hits[k][i].box);
        g[static_cast<std::size_t>(f.detection)].memberScores.push_back(hits[k][i].score);
      }
    }
  refineToLaserExtent(detections, stack, extent);
  for (std::size_t i = 0; i < detections.size(); ++i) {
    g[i].box = detections[i].box;
    if (regression.fitted()) {
      detections[i].box = regression.refine(g[i], stack);
      detections[i].unitBox = stack.toUnit(detections[i].box);
    }
  }
  if (groups) *groups = std::move(g);
}

void refineAndVerify(std::vector<Detection>& detections, const std::vector<std::vector<RawHit>>& hits,
                     std::vector<std::vector<HitFate>>& fates, const LayerStack& stack, const DetectionSetup& setup) {
  std::vector<GroupedBox> formed;  // what the verifier judges: each group before the box regression
  refineBoxes(detections, hits, fates, stack, setup.laserExtent, setup.boxRegression,
              setup.verifier.fitted() ? &formed : nullptr);
  verifyGroups(detections, formed, fates, stack, setup.verifier);
}

namespace {

// Scan, AND chain, group, then refineAndVerify(); `groups` (optional, only for a setup without a
// verifier, whose detections match their groups one to one) gets what formed each detection.
std::vector<Detection> detectAndRefine(const std::vector<const Detector*>& chain, const LayerStack& stack,
                                       const DetectionSetup& setup, std::vector<GroupedBox>* groups,
                                       ScanStats* stats) {
  if (chain.empty()) throw std::invalid_argument("detectChain: no cascade given");
  const Detector& first = *chain.front();
  // One list of hits and fates (refineBoxes() takes one per cascade).
  std::vector<std::vector<RawHit>> hits{first.scan(stack, setup.scan, stats)};
  std::vector<std::vector<HitFate>> fates(1);
  for (std::size_t k = 1; k < chain.size() && !hits[0].empty(); ++k) {
    const Cascade& c = chain[k]->cascade();
    if (c.isOpenCv()) throw std::invalid_argument(c.source + ": an OpenCV cascade cannot be AND-combined");
    const IntegralStack integrals = integrateFor(c, stack);
    std::vector<RawHit> kept;
    for (const RawHit& h : hits[0])
      if (evaluateWindow(c, integrals, h.box).accepted) kept.push_back(h);
    hits[0] = std::move(kept);
  }
  std::vector<Detection> dets = groupHits(hits[0], setup.group, first.cascade().className, stack, &fates[0]);
  if (groups)
    refineBoxes(dets, hits, fates, stack, setup.laserExtent, setup.boxRegression, groups);
  else
    refineAndVerify(dets, hits, fates, stack, setup);
  return dets;
}

}  // namespace

std::vector<Detection> detectChainGroups(const std::vector<const Detector*>& chain, const LayerStack& stack,
                                         const DetectionSetup& setup, std::vector<GroupedBox>& groups,
                                         ScanStats* stats) {
  DetectionSetup unrefined = setup;
  unrefined.boxRegression = {};
  unrefined.verifier = {};
  return detectAndRefine(chain, stack, unrefined, &groups, stats);
}

std::vector<Detection> detectChain(const std::vector<const Detector*>& chain, const LayerStack& stack,
                                   const DetectionSetup& setup, ScanStats* stats) {
  return detectAndRefine(chain, stack, setup, nullptr, stats);
}

BoxRegression fitBoxRefinement(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                               const std::vector<std::size_t>& indices, const MatchConfig& match,
                               const DetectionSetup& setup, const BoxFitParams& params) {
  std::vector<std::vector<double>> features;
  std::vector<BoxTargets> targets;
  for (std::size_t i : indices) {
    const DatasetItem& item = items.at(i);
    std::vector<GroupedBox> groups;
    const std::vector<Detection> dets = detectChainGroups(chain, item.stack, setup, groups);
    const StackMatch m = matchDetections(dets, item.labels, match);  // the label roles (moderate, class)
    for (std::size_t d = 0; d < dets.size(); ++d) {
      double best = 0;
      const Label* truth = nullptr;
      for (std::size_t l = 0; l < item.labels.size(); ++l) {
        if (m.labelRoles[l] != LabelRole::kPositive) continue;
        const double o = iou(dets[d].box, item.labels[l].box);
        if (o > best) best = o, truth = &item.labels[l];
      }
      if (!truth || best < params.minIou || !(dets[d].box.w > 0) || !(dets[d].box.h > 0)) continue;
      features.push_back(boxFeatures(groups[d], item.stack));
      targets.push_back(boxTargets(dets[d].box, truth->box));
    }
  }
  return fitBoxRegression(features, targets, params);
}

GroupVerifier fitGroupVerification(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                                   const std::vector<std::size_t>& indices, const MatchConfig& match,
                                   const DetectionSetup& setup, const VerifierParams& params) {
  std::vector<std::vector<double>> features;
  std::vector<bool> isHit;
  std::size_t positives = 0;
  DetectionSetup unverified = setup;
  unverified.verifier = {};
  MatchConfig labelling = match;
  if (params.labelIou > 0) labelling.minIou = params.labelIou;
  for (std::size_t i : indices) {
    const DatasetItem& item = items.at(i);
    std::vector<GroupedBox> groups;
    // The boxes the evaluation scores (with the box regression), each with its group before it.
    const std::vector<Detection> dets = detectAndRefine(chain, item.stack, unverified, &groups, nullptr);
    const StackMatch m = matchDetections(dets, item.labels, labelling);
    positives += m.positives;
    for (std::size_t d = 0; d < dets.size(); ++d) {
      if (m.detections[d] == DetectionOutcome::kIgnored) continue;
      features.push_back(groupFeatures(groups[d], item.stack));
      isHit.push_back(m.detections[d] == DetectionOutcome::kHit);
    }
  }
  return fitGroupVerifier(features, isHit, positives, params);
}

EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const std::vector<std::size_t>& indices, const MatchConfig& match,
                          const DetectionSetup& setup) {
  EvalOutcome out;
  double totalMs = 0;
  for (std::size_t i : indices) {
    const DatasetItem& item = items.at(i);
    ScanStats stats;
    const auto t0 = std::chrono::steady_clock::now();
    std::vector<Detection> dets = detectChain(chain, item.stack, setup, &stats);
    totalMs += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    out.windows += stats.windows;
    out.stumps += stats.stumps;
    StackMatch m = matchDetections(dets, item.labels, match);
    out.counts.add(m);
    out.frames.push_back(frameOutcome(dets, m));
    out.detections.push_back(std::move(dets));
    out.matches.push_back(std::move(m));
  }
  out.msPerStack = indices.empty() ? 0.0 : totalMs / static_cast<double>(indices.size());
  return out;
}

EvalOutcome evaluateChain(const std::vector<const Detector*>& chain, const std::vector<DatasetItem>& items,
                          const MatchConfig& match, const DetectionSetup& setup) {
  std::vector<std::size_t> all(items.size());
  std::iota(all.begin(), all.end(), 0);
  return evaluateChain(chain, items, all, match, setup);
}

}  // namespace fusedet::boosting
