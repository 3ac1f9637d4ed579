// Training positives (boost/class_rules.h TrainingPositives): which label becomes a training
// positive under which rule, worked by hand per label; evaluation untouched; the default rule
// gives the labels it gave before; the extra positives reach the trainer; the cache key.

#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/experiments/cross_validation.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/training_set.h"
#include "synthetic_scenes.h"

namespace fusedet::boosting {
namespace {

Label label(std::string cls, std::string source, double h, int occlusion, double truncation) {
  Label l;
  l.className = std::move(cls);
  l.sourceClass = std::move(source);
  l.box = Box{10, 10, 1.5 * h, h};
  l.occlusion = occlusion;
  l.truncation = truncation;
  return l;
}

// Role of one label in training under `rule` (car, devkit evaluation otherwise).
LabelRole trainRole(const Label& l, const std::string& rule, bool levels = false, const std::string& cls = "car") {
  return labelRole(l, trainingMatchConfig(matchConfigFor(cls), parseTrainingPositives(rule), levels));
}

constexpr LabelRole kPos = LabelRole::kPositive;
constexpr LabelRole kIgn = LabelRole::kIgnoredLabel;

TEST(TrainingPositives, ParsesAndPrintsTheRule) {
  EXPECT_TRUE(parseTrainingPositives("moderate").isDefault());
  const TrainingPositives all = parseTrainingPositives("hard,vans,min-height=18");
  EXPECT_EQ(all.level, TrainingPositives::Level::kHard);
  EXPECT_TRUE(all.vans);
  EXPECT_EQ(all.minHeight, 18);
  EXPECT_FALSE(all.isDefault());
  EXPECT_EQ(toString(all), "hard,vans,min-height=18");
  EXPECT_EQ(toString(parseTrainingPositives("hard,min-height=18.5,vans")), "hard,vans,min-height=18.5");
  EXPECT_EQ(toString(TrainingPositives{}), "moderate");
  EXPECT_EQ(toString(parseTrainingPositives("moderate,vans")), "moderate,vans");
  for (const char* bad : {"", "easy", "hard,", ",hard", "hard,vans,vans", "hard,min-height=0", "hard,min-height=-3",
                          "hard,min-height=18px", "hard,min-height=", "hard,min-height=nan", "hard,trucks",
                          "hard,min-height=18,min-height=20"})
    EXPECT_THROW(parseTrainingPositives(bad), std::invalid_argument) << bad;
}

TEST(TrainingPositives, WorkedExamplesPerLevel) {
  // Object-benchmark labels (truncation a fraction), 30 px high unless said.
  const Label clean = label("car", "Car", 30, 0, 0.0);
  const Label occluded2 = label("car", "Car", 30, 2, 0.0);     // KITTI hard, not moderate
  const Label occluded3 = label("car", "Car", 30, 3, 0.0);     // unknown occlusion: never
  const Label truncated04 = label("car", "Car", 30, 0, 0.4);   // hard (<= 0.5), not moderate (> 0.3)
  const Label truncated03 = label("car", "Car", 30, 0, 0.3);   // moderate's limit itself
  const Label truncated06 = label("car", "Car", 30, 0, 0.6);   // beyond hard
  const Label low20 = label("car", "Car", 20, 0, 0.0);         // 18-25 px
  const Label low17 = label("car", "Car", 17, 0, 0.0);         // below 18 px
  EXPECT_EQ(trainRole(clean, "moderate"), kPos);
  EXPECT_EQ(trainRole(clean, "hard"), kPos);
  EXPECT_EQ(trainRole(occluded2, "moderate"), kIgn);
  EXPECT_EQ(trainRole(occluded2, "hard"), kPos);
  EXPECT_EQ(trainRole(occluded3, "hard"), kIgn);
  EXPECT_EQ(trainRole(truncated03, "moderate"), kPos);
  EXPECT_EQ(trainRole(truncated04, "moderate"), kIgn);
  EXPECT_EQ(trainRole(truncated04, "hard"), kPos);
  EXPECT_EQ(trainRole(truncated06, "hard"), kIgn);
  EXPECT_EQ(trainRole(low20, "hard"), kIgn);
  EXPECT_EQ(trainRole(low20, "hard,min-height=18"), kPos);
  EXPECT_EQ(trainRole(low20, "moderate,min-height=18"), kPos);
  EXPECT_EQ(trainRole(low17, "hard,min-height=18"), kIgn);
  // The lower minimum height keeps the level's other limits.
  EXPECT_EQ(trainRole(label("car", "Car", 20, 2, 0.0), "moderate,min-height=18"), kIgn);
  EXPECT_EQ(trainRole(label("car", "Car", 20, 2, 0.0), "hard,min-height=18"), kPos);
}

TEST(TrainingPositives, TrackingTruncationLevels) {
  // KITTI tracking labels (drives 0005, 0009) store truncation as a level 0, 1, 2.
  const Label level0 = label("car", "Car", 30, 0, 0), level1 = label("car", "Car", 30, 0, 1),
              level2 = label("car", "Car", 30, 0, 2);
  // Moderate: level 0 only, as in evaluation, whether or not the levels are known.
  EXPECT_EQ(trainRole(level0, "moderate", true), kPos);
  EXPECT_EQ(trainRole(level1, "moderate", true), kIgn);
  EXPECT_EQ(trainRole(level1, "moderate", false), kIgn);
  // Hard: levels 0 and 1 where the labels are known to carry levels.
  EXPECT_EQ(trainRole(level0, "hard", true), kPos);
  EXPECT_EQ(trainRole(level1, "hard", true), kPos);
  EXPECT_EQ(trainRole(level2, "hard", true), kIgn);
  // Read as a fraction, 1 is fully truncated: not a hard positive.
  EXPECT_EQ(trainRole(level1, "hard", false), kIgn);
  EXPECT_EQ(trainingMatchConfig(matchConfigFor("car"), parseTrainingPositives("hard"), true).maxTruncation, 1);
  EXPECT_EQ(trainingMatchConfig(matchConfigFor("car"), parseTrainingPositives("hard"), false).maxTruncation, 0.5);
}

TEST(TrainingPositives, VansTrainAsCarsOnlyWithVans) {
  const Label van = label("van", "Van", 40, 0, 0.0), occludedVan = label("van", "Van", 40, 2, 0.0),
              lowVan = label("van", "Van", 20, 0, 0.0);
  EXPECT_EQ(trainRole(van, "moderate"), kIgn);  // the devkit's neighbouring class
  EXPECT_EQ(trainRole(van, "hard"), kIgn);
  EXPECT_EQ(trainRole(van, "moderate,vans"), kPos);
  EXPECT_EQ(trainRole(occludedVan, "moderate,vans"), kIgn);  // the level's limits hold for vans too
  EXPECT_EQ(trainRole(occludedVan, "hard,vans"), kPos);
  EXPECT_EQ(trainRole(lowVan, "hard,vans"), kIgn);
  EXPECT_EQ(trainRole(lowVan, "hard,vans,min-height=18"), kPos);
  // As training labels: the van is renamed to car, a positive the trainer takes.
  const Labels t = trainingLabels({van}, trainingMatchConfig(matchConfigFor("car"), parseTrainingPositives("hard,vans")));
  ASSERT_EQ(t.size(), 1u);
  EXPECT_EQ(t[0].className, "car");
  EXPECT_FALSE(t[0].ignore);
  EXPECT_EQ(t[0].sourceClass, "Van");
  // Vans are car's neighbours only.
  EXPECT_THROW(trainingMatchConfig(matchConfigFor("person"), parseTrainingPositives("hard,vans")), std::invalid_argument);
  EXPECT_NO_THROW(trainingMatchConfig(matchConfigFor("person"), parseTrainingPositives("hard,min-height=18")));
}

TEST(TrainingPositives, EvaluationIsUntouched) {
  const MatchConfig eval = matchConfigFor("car");
  const MatchConfig wide = trainingMatchConfig(eval, parseTrainingPositives("hard,vans,min-height=18"));
  EXPECT_EQ(wide.maxOcclusion, 2);
  EXPECT_EQ(wide.minHeight, 18);
  // The evaluation's configuration is a value: the devkit's rules stand for it.
  const MatchConfig again = matchConfigFor("car");
  EXPECT_EQ(eval.minHeight, 25);
  EXPECT_EQ(eval.maxOcclusion, 1);
  EXPECT_EQ(eval.maxTruncation, 0.3);
  EXPECT_EQ(eval.neighbourClasses, again.neighbourClasses);
  EXPECT_TRUE(eval.aliasClasses.empty());
  EXPECT_EQ(labelRole(label("van", "Van", 40, 0, 0.0), eval), kIgn);
  EXPECT_EQ(labelRole(label("car", "Car", 30, 2, 0.0), eval), kIgn);
  // Same hit overlap, detection height, DontCare and false-alarm classes as evaluation.
  EXPECT_EQ(wide.minIou, eval.minIou);
  EXPECT_EQ(wide.minDetectionHeight, eval.minDetectionHeight);
  EXPECT_EQ(wide.falseAlarmClasses, eval.falseAlarmClasses);
  EXPECT_EQ(wide.ignoreClasses, eval.ignoreClasses);
}

TEST(TrainingPositives, DefaultGivesTheLabelsTrainingHadBefore) {
  Labels labels{label("car", "Car", 30, 0, 0.0),  label("car", "Car", 30, 2, 0.0), label("car", "Car", 20, 0, 0.0),
                label("car", "Car", 30, 0, 0.4),  label("car", "Car", 30, 0, 1),   label("van", "Van", 40, 0, 0.0),
                label("", "Truck", 50, 0, 0.0),   label("", "DontCare", 30, -1, -1)};
  labels[6].ignore = labels[7].ignore = true;
  for (bool levels : {false, true})
    for (VanPolicy van : {VanPolicy::kIgnore, VanPolicy::kNegative, VanPolicy::kPositive}) {
      const MatchConfig eval = matchConfigFor("car", van);
      const Labels before = trainingLabels(labels, eval);
      const Labels now = trainingLabels(labels, trainingMatchConfig(eval, TrainingPositives{}, levels));
      ASSERT_EQ(now.size(), before.size());
      for (std::size_t i = 0; i < now.size(); ++i) {
        EXPECT_EQ(now[i].className, before[i].className);
        EXPECT_EQ(now[i].sourceClass, before[i].sourceClass);
        EXPECT_EQ(now[i].ignore, before[i].ignore);
        EXPECT_EQ(now[i].box.h, before[i].box.h);
      }
    }
  // Exactly one positive under the default (the clean car), four more cars under hard,min-height=18
  // (occluded 2, 20 px, truncated 0.4; the fraction 1 stays out), and the van with vans.
  const auto positives = [&](const std::string& rule) {
    std::size_t n = 0;
    for (const Label& l : trainingLabels(labels, trainingMatchConfig(matchConfigFor("car"), parseTrainingPositives(rule))))
      n += !l.ignore && l.className == "car";
    return n;
  };
  EXPECT_EQ(positives("moderate"), 1u);
  EXPECT_EQ(positives("hard"), 3u);
  EXPECT_EQ(positives("hard,min-height=18"), 4u);
  EXPECT_EQ(positives("hard,vans,min-height=18"), 5u);
}

TEST(TrainingPositives, CacheKeyKeepsTheDefaultAndSeparatesRules) {
  TrainingConfig plain = synthetic::smallConfig();
  const std::vector<std::string> ids{"x/1", "x/2"};
  EXPECT_EQ(describeTrainingConfig(plain).find("training_positives"), std::string::npos);
  TrainingConfig vans = plain;
  vans.trainingPositives = "moderate,vans";  // same limits as the default: only the rule differs
  EXPECT_NE(describeTrainingConfig(vans).find("training_positives moderate,vans"), std::string::npos);
  EXPECT_NE(trainingKey(plain, ids), trainingKey(vans, ids));
}

// Cars occluded at level 2 (KITTI hard): under the default rule they are ignored labels, under
// "hard" they are positives the trainer samples (each with its mirrored copy).
TEST(TrainingPositives, ExtraPositivesReachTheTrainer) {
  std::vector<DatasetItem> items = synthetic::scenes(8, false);
  std::size_t clean = 0, hard = 0, vans = 0;
  for (DatasetItem& item : items)
    for (std::size_t k = 0; k < item.labels.size(); ++k) {
      Label& l = item.labels[k];
      if (l.className == "van") ++vans;
      if (l.className != "car") continue;
      if (k % 2 == 1) {
        l.occlusion = 2;
        ++hard;
      } else {
        ++clean;
      }
    }
  ASSERT_GT(clean, 0u);
  ASSERT_GT(hard, 0u);
  ASSERT_GT(vans, 0u);
  MatchConfig eval = matchConfigFor("car");
  eval.minHeight = 20;  // the synthetic cars are 24 px high
  TrainingConfig c = synthetic::smallConfig();
  c.maxStages = 1;
  c.threads = 1;
  const auto train = [&](const std::string& ruleText, std::size_t* stackPositives) {
    const TrainingPositives rule = parseTrainingPositives(ruleText);
    const MatchConfig m = trainingMatchConfig(eval, rule);
    std::vector<DatasetItem> mapped = items;
    for (DatasetItem& item : mapped) item.labels = trainingLabels(item.labels, m);
    TrainingConfig tc = c;
    tc.samples.minPositiveHeight = m.minHeight;
    tc.samples.maxOcclusion = m.maxOcclusion;
    *stackPositives = TrainingStacks(mapped, {"intensity"}, std::nullopt, tc.samples).positives().size();
    NullProgress quiet;
    TrainingReport report;
    trainCascade(tc, mapped, quiet, &report);
    return report.positives;
  };
  std::size_t stacks = 0;
  EXPECT_EQ(train("moderate", &stacks), 2 * clean);  // mirrored copies: 2 per label
  EXPECT_EQ(stacks, 2 * clean);
  EXPECT_EQ(train("hard", &stacks), 2 * (clean + hard));
  EXPECT_EQ(stacks, 2 * (clean + hard));
  EXPECT_EQ(train("hard,vans", &stacks), 2 * (clean + hard + vans));

  // Through the fold-model cache: its own key, the rule written into the cached model.
  const std::filesystem::path cache = std::filesystem::temp_directory_path() / "fusedet_training_positives_test";
  std::filesystem::remove_all(cache);
  std::vector<std::size_t> every(items.size());
  for (std::size_t i = 0; i < every.size(); ++i) every[i] = i;
  TrainingConfig hc = c;
  hc.samples.maxOcclusion = 2;
  hc.trainingPositives = "hard";
  std::vector<DatasetItem> mapped = items;
  for (DatasetItem& item : mapped)
    item.labels = trainingLabels(item.labels, trainingMatchConfig(eval, parseTrainingPositives("hard")));
  NullProgress quiet;
  FoldModel source;
  trainOrLoad(hc, mapped, every, cache, quiet, nullptr, nullptr, &source);
  const ModelInfo info = loadModelInfo(cache / (source.key + ".json"));
  bool found = false;
  for (const auto& [k, v] : info)
    if (k == "training_positives") found = v == "hard";
  EXPECT_TRUE(found);
  std::filesystem::remove_all(cache);
}

}  // namespace
}  // namespace fusedet::boosting
