// SPDX-License-Identifier: Apache-2.0
// Training on proposals (SampleConfig::windows kProposals): the negatives are the training stacks'
// label-free proposals of the class (counted by hand here), never scan windows, and a cascade
// trained so records its window search and verifies a held-out stack's proposals: it keeps the
// proposal on the object and drops the ones on background.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "fusedet/boost/cascade_trainer.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/proposal_windows.h"
#include "fusedet/boost/training_set.h"

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

Detection proposal(const std::string& cls, double score, Box box) {
  Detection d;
  d.className = cls;
  d.score = score;
  d.box = box;
  return d;
}

// 160 x 48, layer "v": noise in [0, 0.2); the object (20 x 24 at x0, y 12) is 1 in its middle
// column (x0 + 7 to x0 + 13) and 0 beside it, the same mirrored. Label and a proposal on it;
// proposals on background.
DatasetItem scene(int n, std::mt19937& rng) {
  std::uniform_real_distribution<float> noise(0, 0.2f);
  DatasetItem item;
  item.id = "s/" + std::to_string(n);
  item.group = "g" + std::to_string(n);
  item.stack.setReferenceSize(160, 48);
  cv::Mat v(48, 160, CV_32F);
  for (int y = 0; y < 48; ++y)
    for (int x = 0; x < 160; ++x) v.at<float>(y, x) = noise(rng);
  const int x0 = 10 + static_cast<int>(rng() % 100);
  v(cv::Rect(x0, 12, 20, 24)).setTo(0);
  v(cv::Rect(x0 + 7, 12, 6, 24)).setTo(1);
  item.stack.set(Layer{"v", v, {}});
  item.labels.push_back(Label{"car", "Car", Box{double(x0), 12, 20, 24}, 0, 0, false, "human"});
  item.stack.proposals.push_back(proposal("car", 0.6, Box{double(x0) + 1, 12, 20, 24}));
  for (int k = 0; k < 4; ++k) {
    const double px = (x0 + 30 + 30 * k) % 140;
    if (std::abs(px - x0) < 25) continue;
    item.stack.proposals.push_back(proposal("car", 0.4, Box{px, 8, 20, 30}));
  }
  return item;
}

TrainingConfig config() {
  TrainingConfig c;
  c.className = "car";
  c.pool.grid = 4;
  c.pool.layers = {"v"};
  c.pool.types = {FeatureType::kEdgeHorizontal, FeatureType::kLineHorizontal};
  c.samples.windows = WindowSearch::kProposals;
  c.samples.proposalMinScore = 0.3;
  c.samples.minPositiveHeight = 10;
  c.minPositives = 1;
  c.minNegatives = 1;
  c.maxStages = 3;
  c.threads = 1;
  c.stage.threads = 1;
  return c;
}

TEST(ProposalTraining, NegativesAreTheLabelFreeProposalsOfTheClass) {
  DatasetItem item;
  item.id = "a/1";
  item.stack.setReferenceSize(100, 40);
  item.stack.set(Layer{"v", cv::Mat(40, 100, CV_32F, cv::Scalar(0.5)), {}});
  item.labels.push_back(Label{"car", "Car", Box{10, 10, 20, 20}, 0, 0, false, "human"});
  item.labels.push_back(Label{"DontCare", "DontCare", Box{70, 0, 30, 40}, 0, 0, true, "human"});
  item.stack.proposals = {
      proposal("car", 0.9, Box{11, 10, 20, 20}),    // on the label (IoU >= 0.3): no negative
      proposal("car", 0.5, Box{40, 10, 20, 20}),    // background: a negative
      proposal("car", 0.5, Box{40, 5, 10, 30}),     // background: a negative
      proposal("car", 0.5, Box{72, 5, 20, 20}),     // inside the ignore region: no negative
      proposal("car", 0.2, Box{45, 5, 20, 20}),     // below the score: no window
      proposal("person", 0.9, Box{50, 5, 10, 30}),  // another class: no window
  };
  SampleConfig sc = config().samples;
  const TrainingStacks stacks({item}, {"v"}, std::nullopt, sc);
  Cascade none;  // no stage yet: every window is a candidate
  none.layers = {"v"};
  const NegativeHarvest h = stacks.harvestNegatives(none, 100, 1, 1);
  EXPECT_EQ(h.windowsScanned, 4u);
  ASSERT_EQ(h.candidates, 2u);
  ASSERT_EQ(h.samples.size(), 2u);
  EXPECT_EQ(h.samples[0].window, (Box{40, 10, 20, 20}));
  EXPECT_EQ(h.samples[1].window, (Box{40, 5, 10, 30}));
  // The mirrored copy (positives) has its proposals mirrored too.
  const DatasetItem flipped = flipItem(item);
  EXPECT_EQ(flipped.stack.proposals[1].box, (Box{40, 10, 20, 20}));
  EXPECT_EQ(flipped.stack.proposals[0].box, (Box{69, 10, 20, 20}));
}

TEST(ProposalTraining, TheCascadeRecordsItsSearchAndVerifiesHeldOutProposals) {
  std::mt19937 rng(3);
  std::vector<DatasetItem> train;
  for (int n = 0; n < 16; ++n) train.push_back(scene(n, rng));
  NullProgress quiet;
  TrainingReport report;
  const Cascade c = trainCascade(config(), train, quiet, &report);
  EXPECT_EQ(c.windows, WindowSearch::kProposals);
  EXPECT_EQ(c.proposalMinScore, 0.3);
  ASSERT_FALSE(report.stages.empty());
  // Stage 1's candidates: every background proposal of the training scenes, nothing else.
  std::size_t background = 0;
  for (const DatasetItem& it : train) background += it.stack.proposals.size() - 1;
  EXPECT_EQ(report.stages[0].negativeCandidates, background);
  EXPECT_EQ(report.stages[0].windowsScanned, background + train.size());
  // Positives: each label and the proposal on it (IoU 19 / 21), each also mirrored.
  EXPECT_EQ(report.positives, 4 * train.size());
  const Cascade back = modelFromText(modelToText(c, {}), "m.json");
  EXPECT_EQ(back.windows, WindowSearch::kProposals);
  EXPECT_EQ(back.proposalMinScore, 0.3);

  for (int n = 100; n < 104; ++n) {
    const DatasetItem test = scene(n, rng);
    const std::vector<Detection> d = verifyProposals({&back}, test.stack);
    ASSERT_EQ(d.size(), 1u) << test.id;
    EXPECT_EQ(d[0].box, test.stack.proposals[0].box);
    EXPECT_EQ(d[0].score, 0.6);
  }
}

}  // namespace
