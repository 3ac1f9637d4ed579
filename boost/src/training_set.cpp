#include "fusedet/boost/training_set.h"

#include <opencv2/core.hpp>

#include <algorithm>
#include <random>
#include <stdexcept>

namespace fusedet::boosting {

bool isPositiveLabel(const Label& label, const SampleConfig& c) {
  return !label.ignore && label.className == c.className && label.box.h >= c.minPositiveHeight &&
         label.occlusion <= c.maxOcclusion && label.box.w > 0;
}

bool isNegativeWindow(const Box& window, const Labels& labels, const SampleConfig& c) {
  for (const Label& l : labels) {
    if (l.ignore) {
      if (coverage(window, l.box) > c.maxIgnoreCoverage) return false;
    } else if (l.className == c.className && iou(window, l.box) >= c.maxNegativeIou) {
      return false;
    }
  }
  return true;
}

DatasetItem flipItem(const DatasetItem& item) {
  DatasetItem out;
  out.id = item.id + "#flipped";
  out.group = item.group;
  out.stack.setReferenceSize(item.stack.width(), item.stack.height());
  out.stack.id = item.stack.id;
  out.stack.stamp = item.stack.stamp;
  out.stack.source = item.stack.source + " (mirrored)";
  for (const Layer& l : item.stack.layers()) {
    Layer m;
    m.name = l.name;
    cv::flip(l.data, m.data, 1);
    if (l.hasMask()) cv::flip(l.valid, m.valid, 1);
    out.stack.set(std::move(m));
  }
  out.labels = item.labels;
  for (Label& l : out.labels) l.box.x = item.stack.width() - l.box.x - l.box.w;
  return out;
}

TrainingStacks::TrainingStacks(const std::vector<DatasetItem>& items,
                               const std::vector<std::string>& layers,
                               std::optional<double> referenceHue, const SampleConfig& config)
    : config_(config) {
  auto addStack = [&](const DatasetItem& item) {
    const auto index = static_cast<std::uint32_t>(integrals_.size());
    try {
      integrals_.emplace_back(item.stack, layers, referenceHue);
    } catch (const std::exception& e) {
      throw std::runtime_error("training item " + item.id + ": " + e.what());
    }
    labels_.push_back(item.labels);
    for (const Label& l : item.labels)
      if (isPositiveLabel(l, config_)) positives_.push_back(Sample{index, l.box});
  };
  for (const DatasetItem& item : items) addStack(item);
  originals_ = integrals_.size();
  if (config_.flipPositives)
    for (const DatasetItem& item : items)
      if (std::any_of(item.labels.begin(), item.labels.end(),
                      [&](const Label& l) { return isPositiveLabel(l, config_); }))
        addStack(flipItem(item));
}

double TrainingStacks::positiveAspect() const {
  if (positives_.empty()) return 1.0;
  std::vector<double> a;
  for (const Sample& s : positives_) a.push_back(s.window.w / s.window.h);
  std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2), a.end());
  return a[a.size() / 2];
}

NegativeHarvest TrainingStacks::harvestNegatives(const Cascade& cascade, std::size_t wanted,
                                                 std::uint64_t seed, int threads) const {
  Cascade scanWith = cascade;
  if (scanWith.stages.empty()) {
    // No stage yet: a one-stump stage that accepts every window, so the scan visits exactly the
    // windows later stages will (same scales, same steps).
    scanWith.features = {Feature{FeatureType::kEdgeHorizontal, Box{0, 0, 1, 1}, 0}};
    scanWith.stages = {Stage{{Stump{0, 0.0, 1.0, 1.0}}, 0.0}};
  }
  const Detector detector(scanWith);
  ScanParams params = config_.scan;
  params.threads = threads;
  NegativeHarvest h;
  std::mt19937_64 rng(seed);
  for (std::size_t s = 0; s < originals_; ++s) {
    ScanStats stats;
    const std::vector<RawHit> hits = detector.scan(integrals_[s], params, &stats);
    h.windowsScanned += stats.windows;
    for (const RawHit& hit : hits) {
      if (!isNegativeWindow(hit.box, labels_[s], config_)) continue;
      const std::size_t c = h.candidates++;
      const Sample sample{static_cast<std::uint32_t>(s), hit.box};
      if (c < wanted) {
        h.samples.push_back(sample);
      } else {
        const std::uint64_t j = rng() % (c + 1);  // reservoir sampling (Algorithm R)
        if (j < wanted) h.samples[j] = sample;
      }
    }
  }
  return h;
}

}  // namespace fusedet::boosting
