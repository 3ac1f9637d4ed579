// Side-view cascades (TrainingConfig::sideView, cascade.h aspectCascades): which labels become
// positives and negatives, what the trainer builds, and the fold-model cache keys.
#include <gtest/gtest.h>

#include <opencv2/core.hpp>

#include <filesystem>
#include <random>
#include <unistd.h>

#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/cross_validation.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/model_io.h"
#include "synthetic_scenes.h"

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

Label car(double x, double y, double w, double h) {
  Label l;
  l.className = "car";
  l.sourceClass = "Car";
  l.box = Box{x, y, w, h};
  return l;
}

// 200x120 noise with cars of a bright upper and a dark lower half: `narrow` 36x24 (1.5:1) and
// `wide` 60x24 (2.5:1), placed in a fixed left-to-right pattern row by row.
DatasetItem mixedScene(unsigned seed, int narrow, int wide) {
  std::mt19937 rng(seed);
  cv::Mat img(120, 200, CV_8U);
  cv::randu(img, 60, 140);
  DatasetItem item;
  item.id = "mixed/" + std::to_string(seed);
  item.group = "mixed";
  int x = 4 + int(rng() % 8), y = 6 + int(rng() % 8);
  for (int k = 0; k < narrow + wide; ++k) {
    const int w = k < narrow ? 36 : 60;
    if (x + w > 196) {
      x = 4 + int(rng() % 8);
      y += 36;
    }
    img(cv::Rect(x, y, w, 12)) += cv::Scalar(70);
    img(cv::Rect(x, y + 12, w, 12)) -= cv::Scalar(50);
    item.labels.push_back(car(x, y, w, 24));
    x += w + 8 + int(rng() % 6);
  }
  item.stack = LayerStack(200, 120);
  item.stack.set(Layer{"intensity", img, {}});
  return item;
}

std::vector<DatasetItem> mixedScenes(int n) {
  std::vector<DatasetItem> items;
  for (int i = 0; i < n; ++i) items.push_back(mixedScene(300 + unsigned(i), 2, 1));  // 2 narrow, 1 wide each
  return items;
}

TrainingConfig sideViewTraining() {
  TrainingConfig c = synthetic::smallConfig();
  c.maxStages = 2;
  c.threads = 1;
  c.sideView.minAspect = 1.9;
  c.sideView.windowAspect = 2.4;
  return c;
}

}  // namespace

TEST(SideView, OnlyWideLabelsArePositivesAndNarrowOnesStayTheClass) {
  SampleConfig s;
  s.minPositiveAspect = 1.9;
  const Label narrow = car(10, 10, 45, 30), wide = car(100, 10, 66, 30), edge = car(0, 60, 57, 30);
  EXPECT_FALSE(isPositiveLabel(narrow, s));  // 1.5:1
  EXPECT_TRUE(isClassPositive(narrow, s));
  EXPECT_FALSE(isIgnoredLabel(narrow, s));   // a car, not an ignored label
  EXPECT_TRUE(isPositiveLabel(wide, s));     // 2.2:1
  EXPECT_TRUE(isPositiveLabel(edge, s));     // exactly 1.9:1
  s.minPositiveAspect = 0;
  EXPECT_TRUE(isPositiveLabel(narrow, s));
  // Windows on the narrow car are no negatives (IoU >= 0.3), as the base cascade's trainer has it.
  s.minPositiveAspect = 1.9;
  const Labels labels = {narrow, wide};
  EXPECT_FALSE(isNegativeWindow(Box{10, 10, 45, 30}, labels, s));
  EXPECT_FALSE(isNegativeWindow(Box{5, 10, 66, 30}, labels, s));  // a wide window over it: IoU 0.68
  EXPECT_TRUE(isNegativeWindow(Box{40, 60, 66, 30}, labels, s));
}

TEST(SideView, TrainerAddsASecondCascadeAtItsAspectAndLeavesTheFirstAsItWas) {
  const std::vector<DatasetItem> items = mixedScenes(10);
  const TrainingConfig c = sideViewTraining();
  NullProgress quiet;
  const Cascade both = trainCascade(c, items, quiet);
  ASSERT_EQ(both.aspectCascades.size(), 1u);
  Cascade first = both;
  first.aspectCascades.clear();
  EXPECT_EQ(modelToText(first), modelToText(trainCascade(withoutSideView(c), items, quiet)));
  TrainingReport sideReport;
  const Cascade side = trainCascade(sideViewConfig(c), items, quiet, &sideReport);
  EXPECT_EQ(modelToText(both.aspectCascades[0]), modelToText(side));
  // 12 px high windows: the first at the cars' median aspect (2 of 3 are 36x24: 18x12), the side
  // view at 2.4:1 (28.8 -> 29 px); positives = the 10 wide cars and their mirrored copies.
  EXPECT_EQ(both.windowWidth, 18);
  EXPECT_EQ(side.windowWidth, 29);
  EXPECT_EQ(side.windowHeight, 12);
  EXPECT_EQ(sideReport.positives, 20u);
  // On unseen scenes the side-view cascade accepts a window on every wide car (IoU >= 0.5).
  ScanParams p;
  p.scaleFactor = 1.1;
  p.step = 1;
  std::size_t found = 0;
  for (unsigned s = 900; s < 905; ++s) {
    const DatasetItem t = mixedScene(s, 2, 1);
    const std::vector<RawHit> hits = Detector(side).scan(t.stack, p);
    for (const RawHit& h : hits)
      if (iou(h.box, t.labels.back().box) >= 0.5) {
        ++found;
        break;
      }
  }
  EXPECT_EQ(found, 5u);
  // Without wide cars (the 1.5:1 synthetic scenes) there is nothing to train: the first alone.
  EXPECT_TRUE(trainCascade(c, synthetic::scenes(6, false), quiet).aspectCascades.empty());
  TrainingConfig withValidation = c;
  withValidation.validation.part = 3;
  EXPECT_THROW(trainCascade(withValidation, items, quiet), std::invalid_argument);
}

TEST(SideView, FoldCacheKeepsTheFirstCascadesKeyAndGivesTheSideViewItsOwn) {
  const std::vector<DatasetItem> items = mixedScenes(8);
  const TrainingConfig c = sideViewTraining();
  const std::vector<std::size_t> train = {0, 1, 2, 3, 4, 5, 6, 7};
  std::vector<std::string> ids;
  for (const DatasetItem& i : items) ids.push_back(i.id);
  TrainingConfig plain = c;
  plain.sideView = {};
  // The first cascade's description (and key) is the one a configuration without the option has.
  EXPECT_EQ(describeTrainingConfig(withoutSideView(c)), describeTrainingConfig(plain));
  EXPECT_EQ(describeTrainingConfig(plain).find("aspect"), std::string::npos);
  // (17 digits: 1.9 is written 1.8999999999999999)
  EXPECT_NE(describeTrainingConfig(sideViewConfig(c)).find("positives min_aspect 1.899"), std::string::npos);
  EXPECT_EQ(describeTrainingConfig(sideViewConfig(c)).find("side_view"), std::string::npos);
  EXPECT_NE(describeTrainingConfig(c).find("side_view min_aspect 1.899"), std::string::npos);
  const std::string baseKey = trainingKey(plain, ids), sideKey = trainingKey(sideViewConfig(c), ids);
  EXPECT_NE(baseKey, sideKey);

  const auto dir = std::filesystem::temp_directory_path() / ("fusedet_side_cache_" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  NullProgress quiet;
  bool cached = true;
  FoldModel first, second;
  const Cascade trained = trainOrLoad(c, items, train, dir, quiet, nullptr, &cached, &first);
  EXPECT_FALSE(cached);
  EXPECT_EQ(first.key, baseKey + "+" + sideKey);
  ASSERT_EQ(trained.aspectCascades.size(), 1u);
  EXPECT_TRUE(std::filesystem::exists(dir / (baseKey + ".json")));
  EXPECT_TRUE(std::filesystem::exists(dir / (sideKey + ".json")));
  // The first cascade's file is what a run without the option writes and reads.
  Cascade firstOnly = trained;
  firstOnly.aspectCascades.clear();
  EXPECT_EQ(modelToText(trainOrLoad(plain, items, train, dir, quiet, nullptr, &cached)), modelToText(firstOnly));
  EXPECT_TRUE(cached);
  const Cascade loaded = trainOrLoad(c, items, train, dir, quiet, nullptr, &cached, &second);
  EXPECT_TRUE(cached);
  EXPECT_TRUE(second.cached);
  EXPECT_EQ(modelToText(loaded), modelToText(trained));
  std::filesystem::remove_all(dir);
}
