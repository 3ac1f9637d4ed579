// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/training_set.h"
#include "fusedet/boost/parallel_for.h"

#include <opencv2/core.hpp>
#include <tbb/blocked_range.h>
#include <tbb/task_arena.h>

#include <algorithm>
#include <exception>
#include <random>
#include <stdexcept>

namespace fusedet::boosting {

bool isPositiveLabel(const Label& label, const SampleConfig& c) {
  return !label.ignore && label.className == c.className && label.box.h >= c.minPositiveHeight &&
         label.occlusion <= c.maxOcclusion && label.box.w > 0;
}

bool isIgnoredLabel(const Label& label, const SampleConfig& c) {
  if (label.ignore) return true;
  if (label.className == c.className) return !isPositiveLabel(label, c);
  return std::find(c.ignoreClasses.begin(), c.ignoreClasses.end(), label.className) != c.ignoreClasses.end();
}

std::vector<std::string> neighbourClasses(const std::string& className) {
  if (className == "car") return {"van"};
  return {};
}

NegativeWindowTest::NegativeWindowTest(const Labels& labels, const SampleConfig& c)
    : maxIgnoreCoverage_(c.maxIgnoreCoverage), maxNegativeIou_(c.maxNegativeIou) {
  for (const Label& l : labels) {
    if (isIgnoredLabel(l, c)) ignored_.push_back(l.box);
    else if (l.className == c.className) positives_.push_back(l.box);
  }
}

bool NegativeWindowTest::operator()(const Box& window) const {
  for (const Box& b : ignored_)
    if (coverage(window, b) > maxIgnoreCoverage_ || coverage(b, window) > maxIgnoreCoverage_) return false;
  for (const Box& b : positives_)
    if (iou(window, b) >= maxNegativeIou_) return false;
  return true;
}

bool isNegativeWindow(const Box& window, const Labels& labels, const SampleConfig& c) {
  return NegativeWindowTest(labels, c)(window);
}

Labels flippedLabels(const DatasetItem& item) {
  Labels out = item.labels;
  for (Label& l : out) l.box.x = item.stack.width() - l.box.x - l.box.w;
  return out;
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
  out.labels = flippedLabels(item);
  return out;
}

TrainingStacks::TrainingStacks(const std::vector<DatasetItem>& items,
                               const std::vector<std::string>& layers,
                               std::optional<double> referenceHue, const SampleConfig& config, Shard shard,
                               int threads)
    : config_(config), shard_(shard) {
  // Stacks: the items, then mirrored copies of the items holding positives. Labels, owners and
  // positives in that order, serially; the integrals in parallel.
  std::vector<std::pair<std::size_t, bool>> source;  // item index, mirrored
  for (std::size_t i = 0; i < items.size(); ++i) source.emplace_back(i, false);
  originals_ = items.size();
  for (std::size_t i = 0; i < items.size(); ++i)
    if (std::any_of(items[i].labels.begin(), items[i].labels.end(),
                    [&](const Label& l) { return isPositiveLabel(l, config_); }))
      source.emplace_back(i, true);
  for (std::size_t k = 0; k < source.size(); ++k) {
    const auto [i, mirrored] = source[k];
    owner_.push_back(static_cast<int>(i % static_cast<std::size_t>(shard_.ranks)));
    Labels labels = items[i].labels;
    if (mirrored) labels = flippedLabels(items[i]);
    for (const Label& l : labels)
      if (isPositiveLabel(l, config_)) positives_.push_back(Sample{static_cast<std::uint32_t>(k), l.box});
    labels_.push_back(std::move(labels));
  }
  integrals_.resize(source.size());
  // A failure is kept per item and the first in item order is thrown after the loop, so the
  // error names the same item whatever order the workers met them in.
  std::vector<std::exception_ptr> failed(source.size());
  auto integrate = [&](std::size_t k) {
    const auto [i, mirrored] = source[k];
    if (!shard_.owns(i)) return;
    try {
      integrals_[k] = mirrored ? IntegralStack(flipItem(items[i]).stack, layers, referenceHue)
                               : IntegralStack(items[i].stack, layers, referenceHue);
    } catch (const std::exception& e) {
      failed[k] = std::make_exception_ptr(std::runtime_error(
          "training item " + (mirrored ? items[i].id + "#flipped" : items[i].id) + ": " + e.what()));
    }
  };
  if (threads == 1) {
    for (std::size_t k = 0; k < source.size(); ++k) integrate(k);
  } else {
    tbb::task_arena arena(threads > 0 ? threads : tbb::task_arena::automatic);
    arena.execute([&] {
      parallelFor(tbb::blocked_range<std::size_t>(0, source.size(), 1),
                        [&](const tbb::blocked_range<std::size_t>& r) {
                          for (std::size_t k = r.begin(); k != r.end(); ++k) integrate(k);
                        });
    });
  }
  for (const std::exception_ptr& e : failed)
    if (e) std::rethrow_exception(e);
}

double TrainingStacks::positiveAspect() const {
  if (positives_.empty()) return 1.0;
  std::vector<double> a;
  for (const Sample& s : positives_) a.push_back(s.window.w / s.window.h);
  std::nth_element(a.begin(), a.begin() + static_cast<std::ptrdiff_t>(a.size() / 2), a.end());
  return a[a.size() / 2];
}

Detector TrainingStacks::harvestDetector(const Cascade& cascade) {
  Cascade scanWith = cascade;
  if (scanWith.stages.empty()) {
    // No stage yet: a one-stump stage that accepts every window, so the scan visits exactly the
    // windows later stages will (same scales, same steps).
    scanWith.features = {Feature{FeatureType::kEdgeHorizontal, Box{0, 0, 1, 1}, 0}};
    scanWith.stages = {Stage{{Stump{0, 0.0, 1.0, 1.0}}, 0.0}};
  }
  return Detector(scanWith);
}

std::vector<Box> TrainingStacks::candidateWindows(const Detector& detector, std::size_t s, int threads,
                                                  std::size_t* scanned) const {
  ScanParams params = config_.scan;
  params.threads = threads;
  ScanStats stats;
  const std::vector<RawHit> hits = detector.scan(integrals_.at(s), params, &stats);
  *scanned += stats.windows;
  const NegativeWindowTest labelFree(labels_[s], config_);
  std::vector<Box> out;
  for (const RawHit& hit : hits)
    if (labelFree(hit.box)) out.push_back(hit.box);
  return out;
}

NegativeHarvest TrainingStacks::harvestNegatives(const Cascade& cascade, std::size_t wanted,
                                                 std::uint64_t seed, int threads) const {
  const Detector detector = harvestDetector(cascade);
  NegativeHarvest h;
  std::mt19937_64 rng(seed);
  for (std::size_t s = 0; s < originals_; ++s) {
    for (const Box& box : candidateWindows(detector, s, threads, &h.windowsScanned)) {
      const std::size_t c = h.candidates++;
      const Sample sample{static_cast<std::uint32_t>(s), box};
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

std::vector<std::size_t> reservoirSlots(std::size_t candidates, std::size_t wanted, std::uint64_t seed) {
  std::vector<std::size_t> slots;
  std::mt19937_64 rng(seed);
  for (std::size_t c = 0; c < candidates; ++c) {
    if (c < wanted) {
      slots.push_back(c);
    } else {
      const std::uint64_t j = rng() % (c + 1);  // the draws of harvestNegatives()
      if (j < wanted) slots[j] = c;
    }
  }
  return slots;
}

}  // namespace fusedet::boosting
