// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/cascade_trainer.h"

#include <gtest/gtest.h>

#include <opencv2/imgproc.hpp>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <random>
#include <unistd.h>

#include "fusedet/boost/class_rules.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/sample_features.h"
#include "synthetic_scenes.h"

using namespace fusedet;
using namespace fusedet::boosting;
using fusedet::synthetic::scene;
using fusedet::synthetic::scenes;
using fusedet::synthetic::smallConfig;
using fusedet::synthetic::twoLayerConfig;

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

// The trainer tests' scenes are the same whatever ran before them in the program: their noise
// once came from OpenCV's per-thread generator, so TrainingScore's cascades found no car when
// the whole program ran in one process (scripts/sanitize) and did when ctest ran each test alone.
TEST(SyntheticScenes, SameSeedSameSceneWhateverRanBefore) {
  const DatasetItem first = synthetic::scene(301, 2, false);
  cv::Mat other(64, 64, CV_8U);
  cv::randu(other, 0, 256);  // what another test may do before: draw from OpenCV's generator
  const DatasetItem again = synthetic::scene(301, 2, false);
  const cv::Mat& a = first.stack.at("intensity").data;
  const cv::Mat& b = again.stack.at("intensity").data;
  ASSERT_EQ(a.size(), b.size());
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a, synthetic::scene(302, 2, false).stack.at("intensity").data, cv::NORM_INF), 0.0);
}

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
  // The class's smallest positive (the scenes' cars are 24 px high), reported.
  EXPECT_EQ(report.minHeight, 24);

  // On unseen scenes: every car found at IoU >= 0.5 among the raw hits, few windows accepted.
  const Found f = findCars(Detector(c), [](DatasetItem&) {});
  EXPECT_GE(double(f.found), 0.8 * double(f.cars)) << f.found << " of " << f.cars << "; " << report.stopReason;
  EXPECT_LT(double(f.hits) / double(f.windows), 0.05);
}

TEST(CascadeTrainer, SameSeedSameDataGivesByteIdenticalModelForAnyThreadCount) {
  const auto items = scenes(8, true);
  TrainingConfig c = twoLayerConfig();
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

// A stage-count sweep cuts trained cascades instead of training again (cross_validation.h
// ChainSpec::keepStages): that is only honest if the cut equals the cascade trained with that limit.
TEST(CascadeTrainer, FirstStagesOfALongerCascadeEqualTrainingWithThatStageLimit) {
  const auto items = scenes(12, true);
  TrainingConfig c = smallConfig();
  c.pool.layers = {"intensity", "hue_distance"};
  c.targetFalseAlarm = 1e-9;  // not the target: the stage limit (or the negatives) ends the trainings
  c.maxStages = 3;
  NullProgress quiet;
  const Cascade three = trainCascade(c, items, quiet);
  ASSERT_GE(three.stages.size(), 2u);  // (these scenes run out of negatives after two)
  for (int limit = 1; limit <= static_cast<int>(three.stages.size()); ++limit) {
    c.maxStages = limit;
    const Cascade trained = trainCascade(c, items, quiet);
    ASSERT_EQ(trained.stages.size(), static_cast<std::size_t>(limit));
    EXPECT_EQ(modelToText(firstStages(three, static_cast<std::size_t>(limit))), modelToText(trained)) << limit;
  }
  EXPECT_EQ(firstStages(three, 7).stages.size(), three.stages.size());  // fewer than asked: all of them
  EXPECT_THROW(firstStages(three, 0), std::invalid_argument);
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
    // Every item lacks the layer: the first in item order is named, whatever the workers' order.
    EXPECT_NE(std::string(e.what()).find("training item synthetic/100: layer 'distance' not in stack"), std::string::npos)
        << e.what();
  }
  c.pool.layers = {"intensity"};
  c.stage.minHit = 1.5;
  EXPECT_THROW(trainCascade(c, items, quiet), std::invalid_argument);
}

// A cascade trained on a network's layers records that network (model file "network"); items of
// different networks, or neural layers of no recorded network, are refused naming the items.
TEST(CascadeTrainer, RecordsTheNetworkOfNeuralLayers) {
  auto items = scenes(8, false);
  const NetworkRecord net{"darknet", 832, 256, {"n.cfg", "n.weights"}, {std::string(64, '1'), std::string(64, '2')}};
  for (DatasetItem& item : items) {
    // A stand-in score layer: the intensity at half resolution, scaled to [0, 1].
    cv::Mat half;
    cv::resize(item.stack.at("intensity").data, half, cv::Size(), 0.5, 0.5, cv::INTER_AREA);
    half.convertTo(half, CV_32F, 1.0 / 255);
    item.stack.set(Layer{"neural_car", half, {}});
    item.stack.network = net;
  }
  TrainingConfig c = smallConfig();
  c.pool.layers = {"intensity", "neural_car"};
  c.maxStages = 1;
  NullProgress quiet;
  const Cascade trained = trainCascade(c, items, quiet);
  EXPECT_EQ(trained.network, net);
  EXPECT_NE(modelToText(trained).find(net.text()), std::string::npos);
  c.pool.layers = {"intensity"};
  EXPECT_TRUE(trainCascade(c, items, quiet).network.empty());  // no neural layer: no network
  c.pool.layers = {"intensity", "neural_car"};
  items[5].stack.network.inputWidth = 1248;
  try {
    trainCascade(c, items, quiet);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(items[5].id + " from " + items[5].stack.network.text()), std::string::npos)
        << e.what();
  }
  items[0].stack.network = {};
  try {
    trainCascade(c, items, quiet);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(items[0].id + " has neural layers from no recorded network"), std::string::npos)
        << e.what();
  }
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

TEST(CascadeTrainer, EveryPositiveIsMirroredOnAStackOfItsOwn) {
  const std::vector<DatasetItem> items = synthetic::scenes(4, false);
  const SampleConfig s = smallConfig().samples;
  const TrainingStacks mirrored(items, {"intensity"}, std::nullopt, s);
  std::size_t labelled = 0, withPositives = 0;
  for (const DatasetItem& item : items) {
    const auto n = std::count_if(item.labels.begin(), item.labels.end(), [&](const Label& l) { return isPositiveLabel(l, s); });
    labelled += static_cast<std::size_t>(n);
    withPositives += n > 0 ? 1 : 0;
  }
  ASSERT_GT(labelled, 0u);
  EXPECT_EQ(mirrored.positives().size(), 2 * labelled);
  EXPECT_EQ(mirrored.size(), items.size() + withPositives);
}

TEST(CascadeTrainer, ReferenceHueIsTheClassesDistinctiveHue) {
  // Hue 210 everywhere; inside the car, 40 % of the pixels red (5 degrees).
  DatasetItem item;
  item.id = "hue/1";
  item.stack = LayerStack(100, 100);
  cv::Mat hue(100, 100, CV_32F, cv::Scalar(210.f));
  hue(cv::Rect(10, 10, 20, 8)).setTo(5.f);
  item.stack.set(Layer{"hue", hue, {}});
  Label car;
  car.className = "car";
  car.box = Box{10, 10, 20, 20};
  item.labels = {car};
  SampleConfig s;
  s.minPositiveHeight = 10;
  // Distinctive: the red over-represented in the car, not its most frequent hue (210, the 215 bin).
  EXPECT_DOUBLE_EQ(classReferenceHue({item}, s), 5.0);
  // The trainer stores that hue in the model.
  const auto items = synthetic::scenes(4, true);
  TrainingConfig c = twoLayerConfig();
  c.maxStages = 1;
  NullProgress quiet;
  const Cascade m = trainCascade(c, items, quiet);
  ASSERT_TRUE(m.referenceHue.has_value());
  EXPECT_DOUBLE_EQ(*m.referenceHue, classReferenceHue(items, c.samples));
}

// Three scenes with two layers at different resolutions: intensity and a half-size "distance"
// made from it by a gain and offset.
static std::vector<DatasetItem> twoLayerScenes(unsigned firstSeed) {
  std::vector<DatasetItem> items;
  for (unsigned s = 0; s < 3; ++s) {
    DatasetItem it = scene(firstSeed + s, 2, false);
    cv::Mat half, f;
    cv::resize(it.stack.at("intensity").data, half, cv::Size(100, 60));
    half.convertTo(f, CV_32F, 0.37, -3.1);
    it.stack.set(Layer{"distance", f, {}});
    items.push_back(it);
  }
  return items;
}

// The stacks' positives plus 40 random windows of repeated and distinct sizes.
static std::vector<Sample> positivesAndRandomWindows(const TrainingStacks& stacks, unsigned seed) {
  std::vector<Sample> samples = stacks.positives();
  std::mt19937 rng(seed);
  for (int k = 0; k < 40; ++k) {
    const double w = 20 + double(rng() % 4) * 7.3, h = w * 0.6;
    samples.push_back(Sample{std::uint32_t(rng() % stacks.size()),
                             Box{double(rng() % 150), double(rng() % 80), w, h}});
  }
  return samples;
}

TEST(SampleFeatures, EqualsFeatureValueBitForBit) {
  const auto items = twoLayerScenes(300);
  SampleConfig sc;
  sc.minPositiveHeight = 20;
  const TrainingStacks stacks(items, {"intensity", "distance"}, std::nullopt, sc);
  PoolConfig pc;
  pc.grid = 7;
  pc.layers = {"intensity", "distance"};
  const auto pool = generatePool(pc);
  const std::vector<Sample> samples = positivesAndRandomWindows(stacks, 3);
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

// The fold-model cache: the first call trains and writes the model under its key, the second
// loads it and reports the training time the file recorded (what a run from the cache would have
// cost without it), not the time of loading.
TEST(TrainOrLoad, SecondCallLoadsTheModelAndItsRecordedTrainingTime) {
  const auto items = scenes(8, true);
  TrainingConfig c = twoLayerConfig();
  const std::vector<std::size_t> train = {0, 1, 2, 3, 4, 5, 6, 7};
  const auto dir = std::filesystem::temp_directory_path() / ("fusedet_fold_cache_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  NullProgress quiet;
  bool cached = true;
  FoldModel first, second;
  TrainingReport report;
  const Cascade trained = trainOrLoad(c, items, train, dir, "", quiet, &report, &cached, &first);
  EXPECT_FALSE(cached);
  EXPECT_FALSE(first.cached);
  EXPECT_EQ(first.key.size(), 16u);
  EXPECT_DOUBLE_EQ(first.trainSeconds, report.seconds);
  ASSERT_TRUE(std::filesystem::exists(dir / (first.key + ".json")));
  double recorded = -1;
  for (const auto& [k, v] : loadModelInfo(dir / (first.key + ".json")))
    if (k == "train_seconds") recorded = std::stod(v);
  ASSERT_GE(recorded, 0);
  const Cascade loaded = trainOrLoad(c, items, train, dir, "", quiet, nullptr, &cached, &second);
  EXPECT_TRUE(cached);
  EXPECT_TRUE(second.cached);
  EXPECT_EQ(second.key, first.key);
  EXPECT_DOUBLE_EQ(second.trainSeconds, recorded);
  EXPECT_EQ(modelToText(loaded), modelToText(trained));
  std::filesystem::remove_all(dir);
}

