#include "fusedet/boost/cascade_trainer.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <random>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/sample_features.h"
#include "synthetic_scenes.h"

using namespace fusedet;
using namespace fusedet::boosting;
using fusedet::synthetic::scene;
using fusedet::synthetic::scenes;
using fusedet::synthetic::smallConfig;

namespace {

class Recorder : public ProgressSink {
 public:
  void onProgress(const ProgressEvent& e) override { events.push_back(e); }
  std::vector<ProgressEvent> events;
};

// Raw hits of `det` on six unseen scenes (changed by `alter` first): cars found at IoU >= 0.5.
struct Found {
  std::size_t found = 0, cars = 0, hits = 0, windows = 0;
};
template <class Alter>
Found findCars(const Detector& det, const Alter& alter) {
  ScanParams p;
  p.scaleFactor = 1.1;
  p.step = 1;
  Found f;
  for (unsigned s = 900; s < 906; ++s) {
    DatasetItem t = scene(s, 2, false);
    alter(t);
    ScanStats stats;
    const auto raw = det.scan(t.stack, p, &stats);
    f.windows += stats.windows;
    f.hits += raw.size();
    for (const Label& l : t.labels) {
      if (l.className != "car") continue;
      ++f.cars;
      for (const RawHit& h : raw)
        if (iou(h.box, l.box) >= 0.5) {
          ++f.found;
          break;
        }
    }
  }
  return f;
}

}  // namespace

TEST(CascadeTrainer, LearnsSyntheticCarsAndReportsItsStop) {
  const auto items = scenes(12, false);
  Recorder rec;
  TrainingReport report;
  const Cascade c = trainCascade(smallConfig(), items, rec, &report);
  EXPECT_EQ(c.className, "car");
  EXPECT_GE(c.stages.size(), 1u);
  EXPECT_LE(c.stages.size(), 3u);
  EXPECT_EQ(report.stages.size(), c.stages.size());
  EXPECT_FALSE(report.stopReason.empty());
  EXPECT_EQ(report.poolSize, poolSize(smallConfig().pool));
  EXPECT_NEAR(double(c.windowWidth) / c.windowHeight, 36.0 / 24, 0.15);
  // 18 cars (3 of 4 scenes hold 2) and their mirrored copies.
  EXPECT_EQ(report.positives, 36u);
  for (const StageReport& s : report.stages) {
    EXPECT_GE(s.hitRate, 0.995);
    if (s.reachedFalseAlarm) {
      EXPECT_LE(s.falseAlarm, 0.5);
    }
  }
  EXPECT_EQ(rec.events.front().kind, ProgressKind::kStart);
  EXPECT_EQ(rec.events.back().kind, ProgressKind::kFinished);

  // On unseen scenes: every car found at IoU >= 0.5 among the raw hits, few windows accepted.
  const Found f = findCars(Detector(c), [](DatasetItem&) {});
  EXPECT_GE(double(f.found), 0.8 * double(f.cars)) << f.found << " of " << f.cars << "; " << report.stopReason;
  EXPECT_LT(double(f.hits) / double(f.windows), 0.05);
}

TEST(CascadeTrainer, SameSeedSameDataGivesByteIdenticalModelForAnyThreadCount) {
  const auto items = scenes(8, true);
  TrainingConfig c = smallConfig();
  c.pool.layers = {"intensity", "hue_distance"};
  c.maxStages = 2;
  c.threads = 1;
  NullProgress quiet;
  const std::string one = modelToText(trainCascade(c, items, quiet), {{"seed", "5"}});
  c.threads = 2;
  const Cascade second = trainCascade(c, items, quiet);
  EXPECT_EQ(modelToText(second, {{"seed", "5"}}), one);
  // And as files, byte for byte.
  const auto dir = std::filesystem::temp_directory_path();
  saveModel(second, dir / "fusedet_det_a.json", {{"seed", "5"}});
  std::ifstream in(dir / "fusedet_det_a.json", std::ios::binary);
  std::ostringstream content;
  content << in.rdbuf();
  const std::string bytes = content.str();
  EXPECT_EQ(bytes, one);
  ASSERT_TRUE(second.referenceHue.has_value());
  EXPECT_DOUBLE_EQ(*second.referenceHue, 205.0);  // the cars' hue, 200, lies in bin 200-210
  c.seed = 6;
  EXPECT_NE(modelToText(trainCascade(c, items, quiet), {{"seed", "5"}}), one);
}

TEST(CascadeTrainer, ClearErrorsForNoPositivesAndMissingLayers) {
  auto items = scenes(4, false);
  TrainingConfig c = smallConfig();
  c.className = "person";
  NullProgress quiet;
  try {
    trainCascade(c, items, quiet);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no positives of class 'person'"), std::string::npos) << e.what();
  }
  c.className = "car";
  c.pool.layers = {"distance"};
  try {
    trainCascade(c, items, quiet);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("training item synthetic/100"), std::string::npos) << e.what();
  }
  c.pool.layers = {"intensity"};
  c.stage.minHit = 1.5;
  EXPECT_THROW(trainCascade(c, items, quiet), std::invalid_argument);
}

TEST(CascadeTrainer, NegativeWindowsAvoidLabelsAndIgnoreRegions) {
  SampleConfig s;
  Labels labels(3);
  labels[0].className = "car";
  labels[0].box = Box{100, 100, 40, 20};
  labels[1].className = "van";
  labels[1].box = Box{0, 0, 40, 20};
  labels[2].ignore = true;
  labels[2].box = Box{200, 0, 50, 50};
  EXPECT_FALSE(isNegativeWindow(Box{105, 100, 40, 20}, labels, s));  // IoU 0.78 with the car
  EXPECT_TRUE(isNegativeWindow(Box{130, 100, 40, 20}, labels, s));   // IoU 0.14
  EXPECT_TRUE(isNegativeWindow(Box{0, 0, 40, 20}, labels, s));       // on the van: hard negative
  EXPECT_FALSE(isNegativeWindow(Box{210, 10, 20, 20}, labels, s));   // inside DontCare
  Label small;
  small.className = "car";
  small.box = Box{0, 0, 30, 20};
  EXPECT_FALSE(isPositiveLabel(small, s));  // below 25 px
  small.box.h = 30;
  EXPECT_TRUE(isPositiveLabel(small, s));
  small.occlusion = 2;
  EXPECT_FALSE(isPositiveLabel(small, s));
}

TEST(CascadeTrainer, WindowsHoldingAnIgnoredLabelAreNoNegatives) {
  SampleConfig s;
  Labels labels(2);
  labels[0].className = "car";  // below 25 px: neither positive nor background
  labels[0].box = Box{100, 100, 30, 20};
  labels[1].className = "van";
  labels[1].box = Box{300, 100, 40, 30};
  ASSERT_TRUE(isIgnoredLabel(labels[0], s));
  // A window 2x larger than the small car, holding all of it: IoU 0.25 < 0.3, yet no negative.
  EXPECT_FALSE(isNegativeWindow(Box{85, 90, 60, 40}, labels, s));
  // 3x larger: IoU 0.11, still holds the whole car.
  EXPECT_FALSE(isNegativeWindow(Box{70, 80, 90, 60}, labels, s));
  // Holding a third of it: a negative.
  EXPECT_TRUE(isNegativeWindow(Box{120, 100, 30, 20}, labels, s));
  // The van is background unless listed as a neighbouring class (KITTI's devkit ignores it).
  EXPECT_TRUE(isNegativeWindow(Box{290, 95, 60, 40}, labels, s));
  s.ignoreClasses = neighbourClasses("car");
  EXPECT_EQ(s.ignoreClasses, std::vector<std::string>{"van"});
  EXPECT_FALSE(isNegativeWindow(Box{290, 95, 60, 40}, labels, s));
  EXPECT_TRUE(neighbourClasses("person").empty());
}

TEST(CascadeTrainer, JitteredPositivesStayNearTheirLabel) {
  std::mt19937_64 rng(5), again(5);
  const Box b{100, 50, 40, 20};
  const std::vector<Box> j = jitteredBoxes(b, 50, 0.05, 0.05, rng);
  ASSERT_EQ(j.size(), 50u);
  bool moved = false;
  for (const Box& x : j) {
    EXPECT_LE(std::abs(x.w / b.w - 1), 0.05 + 1e-12);
    EXPECT_NEAR(x.w / x.h, 2.0, 1e-12);  // aspect kept
    EXPECT_LE(std::abs(x.x + x.w / 2 - 120), 0.05 * 40 + 1e-9);
    EXPECT_LE(std::abs(x.y + x.h / 2 - 60), 0.05 * 20 + 1e-9);
    EXPECT_GT(iou(x, b), 0.8);
    moved = moved || std::abs(x.x - b.x) > 0.1;
  }
  EXPECT_TRUE(moved);
  const std::vector<Box> k = jitteredBoxes(b, 50, 0.05, 0.05, again);
  EXPECT_EQ(k.front().x, j.front().x);  // seeded: the same copies
}

TEST(SampleFeatures, EqualsFeatureValueBitForBit) {
  // Two layers at different resolutions; windows of repeated and distinct sizes.
  std::vector<DatasetItem> items;
  for (unsigned s = 0; s < 3; ++s) {
    DatasetItem it = scene(300 + s, 2, false);
    cv::Mat half;
    cv::resize(it.stack.at("intensity").data, half, cv::Size(100, 60));
    cv::Mat f;
    half.convertTo(f, CV_32F, 0.37, -3.1);
    it.stack.set(Layer{"distance", f, {}});
    items.push_back(it);
  }
  SampleConfig sc;
  sc.minPositiveHeight = 20;
  const TrainingStacks stacks(items, {"intensity", "distance"}, std::nullopt, sc);
  PoolConfig pc;
  pc.grid = 7;
  pc.layers = {"intensity", "distance"};
  const auto pool = generatePool(pc);
  std::vector<Sample> samples = stacks.positives();
  std::mt19937 rng(3);
  for (int k = 0; k < 40; ++k) {
    const double w = 20 + double(rng() % 4) * 7.3, h = w * 0.6;
    samples.push_back(Sample{std::uint32_t(rng() % stacks.size()),
                             Box{double(rng() % 150), double(rng() % 80), w, h}});
  }
  const SampleFeatures sf(stacks, pool, samples);
  const std::size_t first = 13, count = pool.size() - 20, n = samples.size();
  std::vector<float> out(count * n);
  sf.block(first, count, out);
  std::size_t mismatches = 0;
  for (std::size_t k = 0; k < count; ++k)
    for (std::size_t i = 0; i < n; ++i) {
      const float ref = featureValue(stacks.integrals(samples[i].stack), pool[first + k], samples[i].window);
      mismatches += std::memcmp(&ref, &out[k * n + i], sizeof ref) != 0;
    }
  EXPECT_EQ(mismatches, 0u) << "of " << count * n;
  std::vector<float> one(n);
  sf.feature(first + 5, one);
  for (std::size_t i = 0; i < n; ++i) EXPECT_EQ(one[i], out[5 * n + i]);
}

// Contrast-normalised layers: the sample path equals featureValue() on them too (the trainer's
// values are those detection computes).
TEST(SampleFeatures, EqualsFeatureValueBitForBitOnContrastNormalisedLayers) {
  std::vector<DatasetItem> items;
  for (unsigned s = 0; s < 3; ++s) {
    DatasetItem it = scene(310 + s, 2, false);
    cv::Mat half, f;
    cv::resize(it.stack.at("intensity").data, half, cv::Size(100, 60));
    half.convertTo(f, CV_32F, 0.37, -3.1);
    it.stack.set(Layer{"distance", f, {}});
    items.push_back(it);
  }
  SampleConfig sc;
  sc.minPositiveHeight = 20;
  for (const std::vector<bool>& flags : {std::vector<bool>{true, false}, std::vector<bool>{true, true}}) {
    const TrainingStacks stacks(items, {"intensity", "distance"}, std::nullopt, sc, Shard{}, flags);
    ASSERT_TRUE(stacks.integrals(0).layer(0).contrastNormalised);
    PoolConfig pc;
    pc.grid = 6;
    pc.layers = {"intensity", "distance"};
    const auto pool = generatePool(pc);
    std::vector<Sample> samples = stacks.positives();
    std::mt19937 rng(4);
    for (int k = 0; k < 40; ++k) {
      const double w = 20 + double(rng() % 4) * 7.3, h = w * 0.6;
      samples.push_back(Sample{std::uint32_t(rng() % stacks.size()), Box{double(rng() % 150), double(rng() % 80), w, h}});
    }
    const SampleFeatures sf(stacks, pool, samples);
    const std::size_t n = samples.size();
    std::vector<float> out(pool.size() * n);
    sf.block(0, pool.size(), out);
    std::size_t mismatches = 0, differs = 0;
    for (std::size_t k = 0; k < pool.size(); ++k)
      for (std::size_t i = 0; i < n; ++i) {
        const float ref = featureValue(stacks.integrals(samples[i].stack), pool[k], samples[i].window);
        mismatches += std::memcmp(&ref, &out[k * n + i], sizeof ref) != 0;
      }
    // Normalised values are not the raw ones (the division happened).
    const TrainingStacks raw(items, {"intensity", "distance"}, std::nullopt, sc);
    for (std::size_t i = 0; i < n; ++i)
      differs += featureValue(raw.integrals(samples[i].stack), pool[0], samples[i].window) != out[i];
    EXPECT_EQ(mismatches, 0u) << "of " << pool.size() * n;
    EXPECT_GT(differs, n / 2);
  }
}

// Training with contrast normalisation records it in the model (file round trip) and yields a
// cascade that finds the cars in unseen scenes taken with half the contrast and another offset.
TEST(CascadeTrainer, ContrastNormalisedTrainingIsRecordedAndSurvivesAGainChange) {
  const auto items = scenes(12, false);
  TrainingConfig config = smallConfig();
  config.pool.contrastNormalised = {"intensity"};
  NullProgress quiet;
  TrainingReport report;
  const Cascade c = trainCascade(config, items, quiet, &report);
  ASSERT_EQ(c.contrastNormalised, std::vector<bool>{true});
  const Cascade back = modelFromText(modelToText(c), "n.json");
  EXPECT_EQ(back.contrastNormalised, c.contrastNormalised);
  const Found f = findCars(Detector(back), [](DatasetItem& t) {
    cv::Mat dim;
    t.stack.at("intensity").data.convertTo(dim, CV_8U, 0.5, 40);
    t.stack.set(Layer{"intensity", dim, {}});
  });
  EXPECT_GE(double(f.found), 0.8 * double(f.cars)) << f.found << " of " << f.cars << "; " << report.stopReason;
  EXPECT_LT(double(f.hits) / double(f.windows), 0.05);
  // A layer that is not in the pool is refused.
  config.pool.contrastNormalised = {"distance"};
  EXPECT_THROW(trainCascade(config, items, quiet), std::invalid_argument);
}
