// The training score of cross-drive validation (ChainSpec::scoreTrainingItems) on synthetic
// scenes: every fold's cascade run on its own training items, checked against a cascade trained
// here on the same items and a matching written here (greedy by score, IoU >= 0.5, no ignore
// rules: these scenes have none), and a fold that cannot be trained detecting nothing; with
// the miss analysis, where each fold loses the cars of its own training items.

#include <gtest/gtest.h>

#include <algorithm>

#include "fusedet/experiments/cross_validation.h"
#include "fusedet/boost/learning_curve.h"
#include "fusedet/boost/miss_analysis.h"
#include "synthetic_scenes.h"

namespace fusedet::boosting {
namespace {

struct Tally {
  std::size_t hits = 0, falseAlarms = 0, positives = 0;
};

// Cars found by `det` on `item` at IoU >= 0.5, each car at most once, highest score first.
Tally tally(const Detector& det, const DatasetItem& item, const DetectionSetup& setup) {
  std::vector<Detection> dets = detectChain({&det}, item.stack, setup);
  std::sort(dets.begin(), dets.end(), [](const Detection& a, const Detection& b) { return a.score > b.score; });
  Tally t;
  std::vector<bool> taken(item.labels.size(), false);
  for (const Label& l : item.labels) t.positives += l.className == "car" ? 1 : 0;
  for (const Detection& d : dets) {
    bool hit = false;
    for (std::size_t j = 0; j < item.labels.size() && !hit; ++j)
      if (item.labels[j].className == "car" && !taken[j] && iou(d.box, item.labels[j].box) >= 0.5) hit = taken[j] = true;
    ++(hit ? t.hits : t.falseAlarms);
  }
  return t;
}

// Drive "empty": 2 scenes without cars; drive "full": 10 scenes, 2 cars in most. DontCare
// regions are dropped so that the hand-written matching above is the devkit's here.
std::vector<DatasetItem> twoDrives() {
  std::vector<DatasetItem> items;
  for (unsigned s = 0; s < 12; ++s) {
    DatasetItem it = synthetic::scene(300 + s, s < 2 ? 0 : 2, false);
    it.group = s < 2 ? "empty" : "full";
    std::erase_if(it.labels, [](const Label& l) { return l.ignore; });
    items.push_back(std::move(it));
  }
  return items;
}

// Cars of 20 px and more, no ignore rules; every window position, single-window groups kept.
MatchConfig carMatch() {
  MatchConfig match;
  match.className = "car";
  match.minHeight = 20;
  match.minDetectionHeight = 0;
  return match;
}

DetectionSetup fineSetup() {
  DetectionSetup setup;
  setup.scan.scaleFactor = 1.1;
  setup.scan.step = 1;
  setup.group.minNeighbors = 1;
  return setup;
}

// The folds' training configuration: the small synthetic cascade on one thread.
TrainingConfig oneThreadConfig() {
  TrainingConfig config = synthetic::smallConfig();
  config.threads = 1;
  return config;
}

// The cascade a fold trains, trained here on the same items.
Detector trainedLike(const std::vector<DatasetItem>& items, const Fold& fold, const TrainingConfig& config) {
  std::vector<DatasetItem> train;
  for (std::size_t i : fold.train) train.push_back(items[i]);
  NullProgress quiet;
  return Detector(trainCascade(config, train, quiet));
}

std::vector<Fold> foldsOf(const std::vector<DatasetItem>& items) {
  std::vector<std::string> groups;
  for (const auto& it : items) groups.push_back(it.group);
  return crossGroupFolds(groups);
}

TEST(TrainingScore, EachFoldScoredOnItsOwnTrainingItems) {
  const std::vector<DatasetItem> items = twoDrives();
  const std::vector<Fold> folds = foldsOf(items);  // tests "empty", then "full"
  ASSERT_EQ(folds.size(), 2u);
  const MatchConfig match = carMatch();
  const DetectionSetup setup = fineSetup();
  const TrainingConfig config = oneThreadConfig();
  ChainSpec spec{{config}};
  NullProgress quiet;
  const CrossValidationResult plain = crossValidate(spec, items, items, folds, match, setup, {}, quiet);
  EXPECT_TRUE(plain.trainingFrames.empty());
  spec.scoreTrainingItems = true;
  const CrossValidationResult scored = crossValidate(spec, items, items, folds, match, setup, {}, quiet);

  // One outcome per (fold, training item): 10 for the fold that trains on "full", 2 for the other.
  ASSERT_EQ(scored.trainingFrames.size(), 12u);
  // The held-out outcomes do not change.
  ASSERT_EQ(scored.frames.size(), plain.frames.size());
  for (std::size_t i = 0; i < items.size(); ++i) {
    EXPECT_EQ(scored.frames[i].positives, plain.frames[i].positives);
    EXPECT_EQ(scored.frames[i].detections.size(), plain.frames[i].detections.size());
  }
  // Fold 2 trains on the two car-free scenes: no cascade, so nothing detected on them either.
  ASSERT_EQ(scored.failures.size(), 1u);
  for (std::size_t k = 10; k < 12; ++k) {
    EXPECT_TRUE(scored.trainingFrames[k].detections.empty());
    EXPECT_EQ(scored.trainingFrames[k].positives, 0u);
  }
  // Fold 1: the same cascade trained here, run on the same training items, matched by hand.
  const Detector det = trainedLike(items, folds[0], config);
  Tally expected;  // summed over the fold's training items
  std::size_t hits = 0, falseAlarms = 0, positives = 0;
  for (std::size_t k = 0; k < folds[0].train.size(); ++k) {
    const Tally t = tally(det, items[folds[0].train[k]], setup);
    const FrameOutcome& o = scored.trainingFrames[k];
    std::size_t h = 0;
    for (const auto& d : o.detections) h += d.hit ? 1 : 0;
    EXPECT_EQ(o.positives, t.positives) << k;
    EXPECT_EQ(h, t.hits) << k;
    EXPECT_EQ(o.detections.size() - h, t.falseAlarms) << k;
    expected.hits += t.hits;
    expected.positives += t.positives;
    hits += h;
    falseAlarms += o.detections.size() - h;
    positives += o.positives;
  }
  EXPECT_EQ(positives, 20u);  // 10 scenes x 2 cars
  EXPECT_EQ(hits, expected.hits);
  // The score is not trivially empty: the cascade finds some of the cars it was trained on (the
  // grouped boxes of this small 3-stage cascade miss IoU 0.5 on many: 6 of 20 when written).
  EXPECT_GE(hits, 1u) << hits << " hits, " << falseAlarms << " false alarms";
}

TEST(TrainingScore, MissAnalysisOfTheOwnTrainingItems) {
  // As above: "empty" (2 car-free scenes) cannot train, "full" (10 scenes, 2 cars each) can.
  const std::vector<DatasetItem> items = twoDrives();
  std::vector<Fold> folds = foldsOf(items);  // fold 0 trains on "full", tests "empty"
  ASSERT_EQ(folds.size(), 2u);
  std::swap(folds[0], folds[1]);  // the untrainable fold first: its outcomes must come first too
  const MatchConfig match = carMatch();
  const DetectionSetup setup = fineSetup();
  const TrainingConfig config = oneThreadConfig();
  ChainSpec spec{{config}};
  spec.analyseMisses = true;
  NullProgress quiet;
  // Without the training score there is nothing of the training items to explain.
  EXPECT_TRUE(crossValidate(spec, items, items, folds, match, setup, {}, quiet).trainingPositives.empty());
  spec.scoreTrainingItems = true;
  const CrossValidationResult r = crossValidate(spec, items, items, folds, match, setup, {}, quiet);
  ASSERT_EQ(r.trainingPositives.size(), r.trainingFrames.size());
  ASSERT_EQ(r.trainingFrames.size(), 12u);
  // The fold that trains on "empty" has no cascade: nothing on its 2 items (no cars there).
  for (std::size_t k = 0; k < 2; ++k) EXPECT_TRUE(r.trainingPositives[k].empty()) << k;
  // The fold that trains on "full": the analysis of a cascade trained here on the same items,
  // called directly, and the training score's hits, item by item.
  const Detector det = trainedLike(items, folds[1], config);
  std::size_t explained = 0, missed = 0;
  for (std::size_t k = 0; k < folds[1].train.size(); ++k) {
    const DatasetItem& item = items[folds[1].train[k]];
    const std::vector<PositiveOutcome>& got = r.trainingPositives[2 + k];
    const FrameMissAnalysis want = analyseMisses(det, item.stack, item.labels, match, setup);
    ASSERT_EQ(got.size(), want.positives.size()) << k;
    ASSERT_EQ(got.size(), r.trainingFrames[2 + k].positives) << k;
    std::size_t hits = 0;
    for (const auto& d : r.trainingFrames[2 + k].detections) hits += d.hit ? 1 : 0;
    std::size_t hitPositives = 0;
    for (std::size_t j = 0; j < got.size(); ++j) {
      EXPECT_EQ(got[j].hit, want.positives[j].hit) << k << " " << j;
      EXPECT_EQ(got[j].cause, want.positives[j].cause) << k << " " << j;
      hitPositives += got[j].hit ? 1 : 0;
      missed += got[j].hit ? 0 : 1;
    }
    EXPECT_EQ(hitPositives, hits) << k;
    explained += got.size();
  }
  EXPECT_EQ(explained, 20u);
  // Summed as the report does: every miss under one cause, none "untrained" in the trained fold.
  const MissBreakdown b = summariseMisses(r.trainingPositives);
  EXPECT_EQ(b.allPositives, 20u);
  EXPECT_EQ(b.allMisses, missed);
  EXPECT_EQ(b.total[static_cast<std::size_t>(MissCause::kUntrained)], 0u);
  EXPECT_GE(missed, 1u);  // 14 of 20 when written (the small cascade's boxes miss IoU 0.5 often)
}

// ChainSpec::boxFit: each trained fold fits the learned box refinement on ITS OWN training items
// with its own cascade (the same fit as fitBoxRefinement() with a cascade trained here on those
// items), an untrained fold fits nothing, and the scored training items are detected with it.
TEST(TrainingScore, BoxRefinementFittedPerFoldOnItsTrainingItems) {
  const std::vector<DatasetItem> items = twoDrives();
  const std::vector<Fold> folds = foldsOf(items);  // fold 0 trains on "full", fold 1 on "empty"
  ASSERT_EQ(folds.size(), 2u);
  const MatchConfig match = carMatch();
  const DetectionSetup setup = fineSetup();
  const TrainingConfig config = oneThreadConfig();
  ChainSpec spec{{config}};
  spec.scoreTrainingItems = true;
  BoxFitParams fit;
  fit.minSamples = 3;
  fit.minIou = 0.2;
  spec.boxFit = fit;
  NullProgress quiet;
  const CrossValidationResult r = crossValidate(spec, items, items, folds, match, setup, {}, quiet);
  ASSERT_EQ(r.boxFits.size(), 1u);  // the untrainable fold has none
  const Detector det = trainedLike(items, folds[0], config);
  const BoxRegression want = fitBoxRefinement({&det}, items, folds[0].train, match, setup, fit);
  ASSERT_TRUE(want.fitted()) << want.why;  // 20 cars, the small cascade finds enough at IoU 0.2
  EXPECT_EQ(r.boxFits[0].samples, want.samples);
  ASSERT_EQ(r.boxFits[0].weights.size(), want.weights.size());
  for (std::size_t j = 0; j < want.weights.size(); ++j)
    for (std::size_t k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(r.boxFits[0].weights[j][k], want.weights[j][k]);
  // The training score of fold 0 is the refined detection's: hits counted by hand on refined boxes.
  DetectionSetup refined = setup;
  refined.boxRegression = want;
  for (std::size_t k = 0; k < folds[0].train.size(); ++k) {
    const Tally t = tally(det, items[folds[0].train[k]], refined);
    std::size_t h = 0;
    for (const auto& d : r.trainingFrames[k].detections) h += d.hit ? 1 : 0;
    EXPECT_EQ(h, t.hits) << k;
    EXPECT_EQ(r.trainingFrames[k].detections.size() - h, t.falseAlarms) << k;
  }
}

// ChainSpec::verifier: each trained fold fits the group verifier on ITS OWN training items with its
// own cascade (the same fit as fitGroupVerification() with a cascade trained here), and the
// held-out items do not inform the fit: replacing them changes nothing.
TEST(TrainingScore, GroupVerifierFittedPerFoldOnItsTrainingItemsOnly) {
  const std::vector<DatasetItem> items = twoDrives();
  const std::vector<Fold> folds = foldsOf(items);  // fold 0 trains on "full", tests "empty"
  ASSERT_EQ(folds.size(), 2u);
  const MatchConfig match = carMatch();
  const DetectionSetup setup = fineSetup();
  const TrainingConfig config = oneThreadConfig();
  ChainSpec spec{{config}};
  VerifierParams params;
  params.minSamples = 3;
  params.labelIou = 0.2;  // the small cascade places its boxes loosely
  spec.verifier = params;
  NullProgress quiet;
  const CrossValidationResult r = crossValidate(spec, items, items, folds, match, setup, {}, quiet);
  ASSERT_EQ(r.verifiers.size(), 1u);  // the untrainable fold has none
  const Detector det = trainedLike(items, folds[0], config);
  const GroupVerifier want = fitGroupVerification({&det}, items, folds[0].train, match, setup, params);
  ASSERT_TRUE(want.fitted()) << want.why;
  EXPECT_GT(want.hits, 0u);
  EXPECT_LT(want.hits, want.samples);
  EXPECT_EQ(r.verifiers[0].samples, want.samples);
  ASSERT_EQ(r.verifiers[0].weights.size(), want.weights.size());
  for (std::size_t j = 0; j < want.weights.size(); ++j) EXPECT_DOUBLE_EQ(r.verifiers[0].weights[j], want.weights[j]);
  EXPECT_DOUBLE_EQ(r.verifiers[0].threshold, want.threshold);
  // The held-out items replaced by scenes full of cars: the same fit.
  std::vector<DatasetItem> changed = items;
  for (std::size_t k = 0; k < folds[0].test.size(); ++k) {
    DatasetItem other = synthetic::scene(900 + static_cast<unsigned>(k), 2, false);
    other.group = changed[folds[0].test[k]].group;
    changed[folds[0].test[k]] = std::move(other);
  }
  const GroupVerifier same = fitGroupVerification({&det}, changed, folds[0].train, match, setup, params);
  EXPECT_EQ(same.samples, want.samples);
  EXPECT_EQ(same.hits, want.hits);
  for (std::size_t j = 0; j < want.weights.size(); ++j) EXPECT_DOUBLE_EQ(same.weights[j], want.weights[j]);
  EXPECT_DOUBLE_EQ(same.intercept, want.intercept);
  // ...while fitting on them would change it.
  std::vector<std::size_t> withTest = folds[0].train;
  withTest.insert(withTest.end(), folds[0].test.begin(), folds[0].test.end());
  EXPECT_NE(fitGroupVerification({&det}, changed, withTest, match, setup, params).samples, want.samples);
}

// A learning-curve point is crossValidate() on the point's folds (a subset of each fold's training
// items): the chain's box fit and verifier are fitted per fold on THAT subset - the same fits as
// with a cascade trained here on the subset -, not on the whole fold's training items, and the
// point's training score runs the fitted chain on the subset alone. (The verifier is the logistic
// one: the gate reads the laser, which these scenes do not have; both are fitted by
// fitGroupVerification() on the same items.)
TEST(TrainingScore, LearningCurvePointFitsItsChainOnThePointsTrainingItemsOnly) {
  const std::vector<DatasetItem> items = twoDrives();
  const std::vector<Fold> folds = foldsOf(items);  // fold 0 trains on "full" (10 scenes, 20 cars)
  ASSERT_EQ(folds.size(), 2u);
  const MatchConfig match = carMatch();
  const DetectionSetup setup = fineSetup();
  const TrainingConfig config = oneThreadConfig();
  std::vector<Labels> labels;
  for (const DatasetItem& it : items) labels.push_back(it.labels);
  const Fold sub = learningPositivesFold(folds[0], positivesPerItem(labels, match), 10, 7);
  ASSERT_LT(sub.train.size(), folds[0].train.size());  // 5 of the 10 scenes
  ASSERT_GE(sub.train.size(), 5u);
  const Detector det = trainedLike(items, sub, config);  // the point's cascade, trained here
  NullProgress quiet;

  // Box fit + verifier: the box fit is the subset's; fitted on the whole fold's training items the
  // same cascade's fit would have more samples.
  ChainSpec spec{{config}};
  spec.scoreTrainingItems = true;
  BoxFitParams fit;
  fit.minSamples = 3;
  fit.minIou = 0.2;
  spec.boxFit = fit;
  VerifierParams verifier;
  verifier.minSamples = 3;
  verifier.labelIou = 0.5;
  spec.verifier = verifier;
  EXPECT_EQ(fittedStepsName(spec), "box fit + logistic verifier");
  const CrossValidationResult r = crossValidate(spec, items, items, {sub, folds[1]}, match, setup, {}, quiet);
  const BoxRegression wantFit = fitBoxRefinement({&det}, items, sub.train, match, setup, fit);
  ASSERT_TRUE(wantFit.fitted()) << wantFit.why;
  ASSERT_EQ(r.boxFits.size(), 1u);  // the fold that trains on "empty" has no cascade
  EXPECT_EQ(r.boxFits[0].samples, wantFit.samples);
  ASSERT_EQ(r.boxFits[0].weights.size(), wantFit.weights.size());
  for (std::size_t j = 0; j < wantFit.weights.size(); ++j)
    for (std::size_t k = 0; k < 4; ++k) EXPECT_DOUBLE_EQ(r.boxFits[0].weights[j][k], wantFit.weights[j][k]);
  EXPECT_GT(fitBoxRefinement({&det}, items, folds[0].train, match, setup, fit).samples, wantFit.samples);
  // On the refined boxes every training detection of the subset hits at 0.5 (10 of 10 when
  // written): the verifier has no false alarm to learn from, so it is not fitted - as here.
  DetectionSetup refined = setup;
  refined.boxRegression = wantFit;
  const GroupVerifier afterFit = fitGroupVerification({&det}, items, sub.train, match, refined, verifier);
  ASSERT_EQ(r.verifiers.size(), 1u);
  EXPECT_EQ(r.verifiers[0].fitted(), afterFit.fitted());
  EXPECT_EQ(r.verifiers[0].samples, afterFit.samples);
  EXPECT_EQ(r.verifiers[0].hits, afterFit.hits);
  const FoldFits fits = countFits(r);
  EXPECT_EQ(fits.trained, 1u);
  EXPECT_EQ(fits.boxFits, 1u);
  EXPECT_EQ(fits.verifiers, afterFit.fitted() ? 1u : 0u);
  // The point's training score: the subset's items only (then the other fold's 10), each detected
  // with the fitted chain.
  ASSERT_EQ(r.trainingFrames.size(), sub.train.size() + folds[1].train.size());
  DetectionSetup chained = refined;
  chained.verifier = afterFit;
  for (std::size_t k = 0; k < sub.train.size(); ++k) {
    const Tally t = tally(det, items[sub.train[k]], chained);
    std::size_t h = 0;
    for (const auto& d : r.trainingFrames[k].detections) h += d.hit ? 1 : 0;
    EXPECT_EQ(h, t.hits) << k;
    EXPECT_EQ(r.trainingFrames[k].detections.size() - h, t.falseAlarms) << k;
  }

  // The verifier alone: fitted on the subset's detections (1 hit of 10 at IoU 0.5 when written),
  // with fewer samples than the whole fold's training items would give.
  ChainSpec verified{{config}};
  verified.verifier = verifier;
  EXPECT_EQ(fittedStepsName(verified), "logistic verifier");
  const CrossValidationResult v = crossValidate(verified, items, items, {sub, folds[1]}, match, setup, {}, quiet);
  const GroupVerifier want = fitGroupVerification({&det}, items, sub.train, match, setup, verifier);
  ASSERT_TRUE(want.fitted()) << want.why;
  ASSERT_EQ(v.verifiers.size(), 1u);
  EXPECT_TRUE(v.boxFits.empty());
  EXPECT_EQ(v.verifiers[0].samples, want.samples);
  EXPECT_EQ(v.verifiers[0].hits, want.hits);
  ASSERT_EQ(v.verifiers[0].weights.size(), want.weights.size());
  for (std::size_t j = 0; j < want.weights.size(); ++j) EXPECT_DOUBLE_EQ(v.verifiers[0].weights[j], want.weights[j]);
  EXPECT_DOUBLE_EQ(v.verifiers[0].intercept, want.intercept);
  EXPECT_DOUBLE_EQ(v.verifiers[0].threshold, want.threshold);
  EXPECT_GT(fitGroupVerification({&det}, items, folds[0].train, match, setup, verifier).samples, want.samples);
  EXPECT_EQ(countFits(v).verifiers, 1u);
  EXPECT_EQ(countFits(v).boxFits, 0u);
}

TEST(TrainingScore, FittedStepsNameAndFitCounts) {
  ChainSpec spec{{oneThreadConfig()}};
  EXPECT_EQ(fittedStepsName(spec), "");
  spec.boxFit = BoxFitParams{};
  EXPECT_EQ(fittedStepsName(spec), "box fit");
  spec.verifier = VerifierParams{};  // logistic by default
  EXPECT_EQ(fittedStepsName(spec), "box fit + logistic verifier");
  spec.boxFit.reset();
  spec.verifier->kind = VerifierParams::Kind::kHeightGate;
  EXPECT_EQ(fittedStepsName(spec), "gate");
  // Counts: trained folds are those with a cascade summary; unfitted steps do not count.
  CrossValidationResult r;
  r.summaries.resize(3);
  r.boxFits.resize(3);  // not fitted
  r.boxFits[1].weights.assign(2, {1, 0, 0, 0});
  r.verifiers.resize(3);
  r.verifiers[0].ready = r.verifiers[2].ready = true;
  const FoldFits f = countFits(r);
  EXPECT_EQ(f.trained, 3u);
  EXPECT_EQ(f.boxFits, 1u);
  EXPECT_EQ(f.verifiers, 2u);
  EXPECT_EQ(countFits(CrossValidationResult{}).trained, 0u);
}

}  // namespace
}  // namespace fusedet::boosting
