// SPDX-License-Identifier: Apache-2.0
// Cascades trained on proposals (fusedet/boost/proposal_windows.h): which of a stack's proposals
// are windows (class, minimum score, cut to the stack, too small after the cut), the chain's
// verdict on a layer whose feature values are worked out by hand, detections with the proposal's
// box and score, and the refusals (a sliding-window cascade cannot verify, a proposal cascade
// cannot scan). Training's negatives from proposals are in tests/boost/train.

#include "fusedet/boost/proposal_windows.h"

#include <gtest/gtest.h>

#include <limits>
#include <stdexcept>

#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/multi_detector.h"

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

// 100 x 40, layer "v": 1 left of x = 50, 0 right of it. Feature a (left half - right half) on the
// whole window is 1 on a window centred on x = 50 and 0 on one inside either part.
LayerStack edgeStack() {
  LayerStack s(100, 40);
  cv::Mat v(40, 100, CV_32F, cv::Scalar(0));
  v.colRange(0, 50).setTo(1);
  s.set(Layer{"v", v, {}});
  s.id = 7;
  s.proposals = {
      proposal("car", 0.9, Box{30, 10, 40, 20}),      // centred on the edge: value 1, accepted
      proposal("car", 0.8, Box{60, 10, 30, 20}),      // right part only: value 0, rejected
      proposal("car", 0.05, Box{30, 10, 40, 20}),     // below the minimum score: no window
      proposal("person", 0.9, Box{30, 10, 40, 20}),   // another class: no window
      proposal("car", 0.7, Box{-20, 10, 140, 20}),    // cut to x 0-100: centred on the edge, accepted
      proposal("car", 0.6, Box{99.5, 0, 10, 10}),     // 0.5 px wide after the cut: no window
      proposal("car", 0.6, Box{10, 10, std::numeric_limits<double>::quiet_NaN(), 10}),  // no window
  };
  return s;
}

// Accepts a window whose left half is brighter than its right half by >= 0.5 on layer "v".
Cascade edgeCascade() {
  Cascade c;
  c.className = "car";
  c.windowWidth = 20;
  c.windowHeight = 10;
  c.layers = {"v"};
  c.windows = WindowSearch::kProposals;
  c.proposalMinScore = 0.1;
  const int f = c.addFeature(Feature{FeatureType::kEdgeHorizontal, Box{0, 0, 1, 1}, 0});
  c.stages.push_back(Stage{{Stump{f, 0.5, -1, 1}}, 0});
  return c;
}

TEST(ProposalWindows, TheClassesBoxesAboveTheScoreCutToTheStack) {
  const LayerStack s = edgeStack();
  const std::vector<ProposalWindow> w = proposalWindows(s, "car", 0.1);
  ASSERT_EQ(w.size(), 3u);
  EXPECT_EQ(w[0].box, (Box{30, 10, 40, 20}));
  EXPECT_EQ(w[0].score, 0.9);
  EXPECT_EQ(w[1].box, (Box{60, 10, 30, 20}));
  EXPECT_EQ(w[2].box, (Box{0, 10, 100, 20}));
  EXPECT_EQ(w[2].score, 0.7);
  EXPECT_EQ(proposalWindows(s, "car", 0.0).size(), 4u);  // the 0.05 one too
  EXPECT_EQ(proposalWindows(s, "person", 0.1).size(), 1u);
  EXPECT_TRUE(proposalWindows(s, "bike", 0.0).empty());
}

TEST(ProposalWindows, TheChainKeepsWhatItAcceptsWithTheProposalsBoxAndScore) {
  const LayerStack s = edgeStack();
  const Cascade c = edgeCascade();
  ScanStats stats;
  const std::vector<Detection> d = verifyProposals({&c}, s, &stats);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].className, "car");
  EXPECT_EQ(d[0].box, (Box{30, 10, 40, 20}));
  EXPECT_EQ(d[0].score, 0.9);
  EXPECT_NEAR(d[0].unitBox.x, 0.3, 1e-12);
  EXPECT_NEAR(d[0].unitBox.h, 0.5, 1e-12);
  EXPECT_EQ(d[0].stackId, 7u);
  EXPECT_EQ(d[1].box, (Box{0, 10, 100, 20}));
  EXPECT_EQ(d[1].score, 0.7);
  EXPECT_EQ(stats.windows, 3u);
  EXPECT_EQ(stats.stumps, 3u);

  // AND: a second cascade that wants the right half brighter rejects everything the first kept.
  Cascade right = c;
  right.stages[0].stumps[0] = Stump{0, -0.5, 1, -1};
  EXPECT_TRUE(verifyProposals({&c, &right}, s, nullptr).empty());
  // A higher minimum score leaves only the 0.9 proposal.
  Cascade strict = c;
  strict.proposalMinScore = 0.85;
  EXPECT_EQ(verifyProposals({&strict}, s).size(), 1u);

  // detectChain runs the same for a proposal cascade (no scan, no grouping).
  const Detector det(c);
  const std::vector<Detection> viaChain = detectChain({&det}, s, DetectionSetup{});
  ASSERT_EQ(viaChain.size(), 2u);
  EXPECT_EQ(viaChain[1].box, d[1].box);
}

TEST(ProposalWindows, SlidingAndProposalCascadesDoNotMix) {
  const LayerStack s = edgeStack();
  Cascade sliding = edgeCascade();
  sliding.windows = WindowSearch::kSliding;
  EXPECT_THROW(verifyProposals({&sliding}, s), std::invalid_argument);
  const Cascade c = edgeCascade();
  EXPECT_THROW(verifyProposals({&c, &sliding}, s), std::invalid_argument);
  EXPECT_THROW(verifyProposals({}, s), std::invalid_argument);
  const Detector det(c);
  try {
    det.scan(s, ScanParams{});
    FAIL() << "a proposal cascade scanned";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("proposals"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MultiDetector(std::vector<Cascade>{c}), std::invalid_argument);
  Cascade bad = c;
  bad.proposalMinScore = 1.5;
  EXPECT_THROW(bad.validate(), std::invalid_argument);
}

}  // namespace
