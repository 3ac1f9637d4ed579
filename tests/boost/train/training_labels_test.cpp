// SPDX-License-Identifier: Apache-2.0
// Training on labels from another data set of the same items (fusedet experiments --train-labels):
// the fold-model cache never hands a model trained on one label set to a run on another, the
// labels are read by item id from the other data set, and a data set of other items is refused.

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <set>
#include <string>

#include "fusedet/boost/data_split.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/experiments/training_labels.h"
#include "synthetic_scenes.h"

namespace fusedet::boosting {
namespace {
namespace fs = std::filesystem;

// Two drives of 5 scenes, 2 cars and one bright "van" each.
std::vector<DatasetItem> twoDrives() {
  std::vector<DatasetItem> items;
  for (unsigned s = 0; s < 10; ++s) {
    DatasetItem it = synthetic::scene(500 + s, 2, false);
    it.group = s < 5 ? "a" : "b";
    items.push_back(std::move(it));
  }
  return items;
}

// A wrong teacher: every van labelled car and every car van.
std::vector<DatasetItem> swapped(std::vector<DatasetItem> items) {
  for (DatasetItem& it : items)
    for (Label& l : it.labels) {
      if (l.className == "car") l.className = "van";
      else if (l.className == "van") l.className = "car";
      l.origin = "teacher";
    }
  return items;
}

std::vector<Labels> labelsOf(const std::vector<DatasetItem>& items) {
  std::vector<Labels> out;
  for (const auto& it : items) out.push_back(it.labels);
  return out;
}

std::size_t detections(const CrossValidationResult& r) {
  std::size_t n = 0;
  for (const auto& f : r.frames) n += f.detections.size();
  return n;
}

TEST(TrainingLabels, CacheKeepsModelsOfOtherTrainingLabelsApart) {
  const std::vector<DatasetItem> items = twoDrives();
  const std::vector<DatasetItem> taught = swapped(items);
  std::vector<std::string> groups;
  for (const auto& it : items) groups.push_back(it.group);
  const std::vector<Fold> folds = crossGroupFolds(groups);
  ASSERT_EQ(folds.size(), 2u);
  TrainingConfig config = synthetic::smallConfig();
  config.threads = 1;
  DetectionSetup setup;
  setup.scan.scaleFactor = 1.1;
  setup.scan.step = 1;
  setup.group.minNeighbors = 1;
  const MatchConfig match = synthetic::carMatch();
  const fs::path dir = fs::temp_directory_path() / ("fusedet_train_labels_cache_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  NullProgress quiet;

  ChainSpec own{{config}};
  const CrossValidationResult human = crossValidate(own, items, items, folds, match, setup, dir, quiet);
  ASSERT_TRUE(human.failures.empty());
  EXPECT_EQ(human.cachedFolds, 0u);

  ChainSpec other{{config}};
  other.trainingLabels = labelsKey(labelsOf(taught));
  const CrossValidationResult teacher = crossValidate(other, taught, items, folds, match, setup, dir, quiet);
  ASSERT_TRUE(teacher.failures.empty());
  // Same configuration, same item ids: only the training labels tell the models apart.
  EXPECT_EQ(teacher.cachedFolds, 0u);
  for (const auto& [key, m] : teacher.models) EXPECT_EQ(human.models.count(key), 0u) << key;
  // Trained on the swapped labels, the cascades find other boxes than the human-label ones.
  const CrossValidationResult uncached = crossValidate(other, taught, items, folds, match, setup, {}, quiet);
  EXPECT_EQ(detections(teacher), detections(uncached));
  EXPECT_NE(detections(teacher), detections(human));

  // A rerun on the same training labels loads both fold models.
  const CrossValidationResult again = crossValidate(other, taught, items, folds, match, setup, dir, quiet);
  EXPECT_EQ(again.cachedFolds, 2u);
  EXPECT_EQ(detections(again), detections(teacher));
  fs::remove_all(dir);
}

TEST(TrainingLabels, LabelsKeySeesEveryField) {
  const std::vector<Labels> base = labelsOf(twoDrives());
  const std::string key = labelsKey(base);
  EXPECT_EQ(key.size(), 16u);
  EXPECT_EQ(labelsKey(base), key);
  std::set<std::string> keys = {key};
  const auto changed = [&](auto change) {
    std::vector<Labels> l = base;
    change(l[3][0]);
    return labelsKey(l);
  };
  keys.insert(changed([](Label& l) { l.origin = "teacher"; }));
  keys.insert(changed([](Label& l) { l.ignore = !l.ignore; }));
  keys.insert(changed([](Label& l) { l.box.x += 0.5; }));
  keys.insert(changed([](Label& l) { l.occlusion += 1; }));
  keys.insert(changed([](Label& l) { l.truncation += 0.1; }));
  keys.insert(changed([](Label& l) { l.className = "bike"; }));
  keys.insert(changed([](Label& l) { l.sourceClass = "Cyclist"; }));
  EXPECT_EQ(keys.size(), 8u);
  // A label moved to the next item is another label set.
  std::vector<Labels> moved = base;
  moved[4].push_back(moved[3].back());
  moved[3].pop_back();
  EXPECT_NE(labelsKey(moved), key);
  // The key of the training labels goes into the fold model's key; without one it is as before.
  TrainingConfig c;
  EXPECT_EQ(trainingKey(c, {"x/1"}), trainingKey(c, {"x/1"}, ""));
  EXPECT_NE(trainingKey(c, {"x/1"}), trainingKey(c, {"x/1"}, key));
  EXPECT_NE(trainingKey(c, {"x/1"}, key), trainingKey(c, {"x/1"}, labelsKey(moved)));
}

TEST(TrainingLabels, ReadByIdFromADataSetOfTheSameItems) {
  const std::vector<DatasetItem> items = twoDrives();
  const fs::path dir = fs::temp_directory_path() / ("fusedet_train_labels_ds_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  // The other data set holds the items in reverse order, with the swapped labels.
  std::vector<DatasetItem> taught = swapped(items);
  for (auto it = taught.rbegin(); it != taught.rend(); ++it) writeDatasetItem(dir / "teacher", *it);
  const std::vector<Labels> read = readTrainingLabels(dir / "teacher", items);
  ASSERT_EQ(read.size(), items.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    ASSERT_EQ(read[i].size(), taught[i].labels.size()) << items[i].id;
    for (std::size_t j = 0; j < read[i].size(); ++j) {
      EXPECT_EQ(read[i][j].className, taught[i].labels[j].className);
      EXPECT_EQ(read[i][j].origin, "teacher");
      EXPECT_EQ(read[i][j].box, taught[i].labels[j].box);
    }
  }

  // A data set without one of the items is refused, naming it.
  for (std::size_t i = 0; i + 1 < items.size(); ++i) writeDatasetItem(dir / "fewer", items[i]);
  try {
    readTrainingLabels(dir / "fewer", items);
    ADD_FAILURE() << "a data set without an item was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(items.back().id), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("fewer"), std::string::npos) << e.what();
  }
  // An item of another image size is another frame.
  std::vector<DatasetItem> resized = items;
  resized[2].stack.setReferenceSize(400, 240);
  for (const auto& it : resized) writeDatasetItem(dir / "resized", it);
  try {
    readTrainingLabels(dir / "resized", items);
    ADD_FAILURE() << "an item of another size was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(items[2].id), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("400x240"), std::string::npos) << e.what();
  }
  // No data set there at all: the data set's own error, naming the folder.
  EXPECT_THROW(readTrainingLabels(dir / "none", items), DatasetError);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fusedet::boosting
