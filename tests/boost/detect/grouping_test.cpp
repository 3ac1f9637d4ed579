// Grouping against its peer (cv::groupRectangles on the same rectangles) and NMS by hand; and the
// integral images of the OpenCV path against cv::integral.

#include "fusedet/boost/grouping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>
#include <random>

#include "../../../boost/src/opencv_pyramid.h"

using namespace fusedet;
using namespace fusedet::boosting;

namespace {

// Clusters of jittered boxes plus scattered singles, as raw cascade hits look.
std::vector<RawHit> randomHits(unsigned seed, int clusters) {
  std::mt19937 rng(seed);
  std::vector<RawHit> hits;
  for (int c = 0; c < clusters; ++c) {
    const int x = int(rng() % 500), y = int(rng() % 300), s = 20 + int(rng() % 100);
    const int n = 1 + int(rng() % 9);
    for (int i = 0; i < n; ++i) {
      const int j = std::max(1, s / 10);
      const int w = s + int(rng() % (2 * j + 1)) - j;
      hits.push_back(RawHit{Box{double(x + int(rng() % (2 * j + 1)) - j), double(y + int(rng() % (2 * j + 1)) - j),
                                double(w), double(w)},
                            double(rng() % 1000) / 100.0, 0});
    }
  }
  std::shuffle(hits.begin(), hits.end(), rng);
  return hits;
}

}  // namespace

TEST(Grouping, OpenCvRuleEqualsCvGroupRectangles) {
  LayerStack stack(640, 480);
  int compared = 0;
  for (unsigned seed = 1; seed <= 40; ++seed) {
    const auto hits = randomHits(seed, 3 + int(seed % 12));
    for (int minNeighbors : {0, 1, 2, 3, 5}) {
      std::vector<cv::Rect> rects;
      for (const RawHit& h : hits) rects.emplace_back(int(h.box.x), int(h.box.y), int(h.box.w), int(h.box.h));
      std::vector<int> weights;
      cv::groupRectangles(rects, weights, minNeighbors, 0.2);
      GroupParams p;
      p.minNeighbors = minNeighbors;
      const auto dets = groupHits(hits, p, "face", stack);
      ASSERT_EQ(dets.size(), rects.size()) << "seed " << seed << " minNeighbors " << minNeighbors;
      for (std::size_t i = 0; i < rects.size(); ++i) {
        EXPECT_EQ(dets[i].box, (Box{double(rects[i].x), double(rects[i].y), double(rects[i].width), double(rects[i].height)}));
        if (minNeighbors > 0) {
          EXPECT_EQ(dets[i].score, weights[i]);
        }
        EXPECT_EQ(dets[i].className, "face");
      }
      compared += int(rects.size());
    }
  }
  EXPECT_GT(compared, 200);
}

TEST(Grouping, NmsKeepsTheBestOfOverlappingHits) {
  LayerStack stack(200, 100);
  stack.id = 7;
  const std::vector<RawHit> hits = {
      {Box{10, 10, 40, 40}, 1.0, 0}, {Box{12, 10, 40, 40}, 3.0, 0},  // overlap: keep the 3.0
      {Box{100, 50, 20, 20}, 0.5, 0},                                 // alone
      {Box{14, 12, 40, 40}, 2.0, 0},                                  // overlaps the 3.0 one too
      {Box{40, 10, 40, 40}, 2.5, 0}};                                 // IoU with 3.0 box below 0.5
  GroupParams p;
  p.method = GroupParams::Method::kNms;
  p.iouThreshold = 0.5;
  const auto d = groupHits(hits, p, "car", stack);
  ASSERT_EQ(d.size(), 3u);
  EXPECT_EQ(d[0].score, 3.0);
  EXPECT_EQ(d[1].score, 2.5);
  EXPECT_EQ(d[2].score, 0.5);
  EXPECT_EQ(d[0].box, (Box{12, 10, 40, 40}));
  EXPECT_EQ(d[0].stackId, 7u);
  EXPECT_DOUBLE_EQ(d[2].unitBox.x, 0.5);
  EXPECT_DOUBLE_EQ(d[2].unitBox.h, 0.2);
}

TEST(Grouping, SmallGroupsMayNeedFewerNeighbours) {
  LayerStack stack(400, 200);
  // A group of two 30 px hits and a group of two 80 px hits, far apart.
  const std::vector<RawHit> hits = {{Box{10, 10, 30, 30}, 1, 0}, {Box{11, 10, 30, 30}, 1, 0},
                                    {Box{200, 50, 80, 80}, 1, 0}, {Box{202, 51, 80, 80}, 1, 0}};
  GroupParams p;
  p.minNeighbors = 3;
  EXPECT_TRUE(groupHits(hits, p, "car", stack).empty());  // both need 4 members
  p.smallHeight = 40;  // groups lower than 40 px need more than 1 member
  p.smallMinNeighbors = 1;
  const auto d = groupHits(hits, p, "car", stack);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].box, (Box{10, 10, 30, 30}));  // mean x 10.5 rounds to even, as OpenCV's cvRound
  EXPECT_EQ(d[0].score, 2);
  p.smallHeight = 81;  // now the 80 px group is "small" too
  EXPECT_EQ(groupHits(hits, p, "car", stack).size(), 2u);
  // Off (smallHeight 0) is cv::groupRectangles' rule whatever smallMinNeighbors says.
  p.smallHeight = 0;
  p.smallMinNeighbors = 0;
  EXPECT_TRUE(groupHits(hits, p, "car", stack).empty());
}

namespace {

// 400 x 200 reference pixels with a distance layer of the same size: `left` m in columns 0..99,
// `right` m from column 100 (two cars side by side, or a car before a wall).
LayerStack twoDepths(float left, float right) {
  LayerStack s(400, 200);
  cv::Mat1f d(200, 400, right);
  d(cv::Rect(0, 0, 100, 200)).setTo(left);
  s.set(Layer{std::string(layer::kDistance), d, {}});
  return s;
}

// A chain of 60 x 40 windows at y 50 from x 20 to x 142, each within the edge rule's reach (eps 0.2
// x (60 + 40) / 2 = 10 px) of the next: one group by cv::groupRectangles' rule. A window's core
// (laser_cells.h) is columns x + 15 .. x + 45, so its median depth is the left one while most of
// those lie left of column 100 (x <= 60) and the right one from x 70.
std::vector<RawHit> chainAcrossTwoDepths() {
  std::vector<RawHit> hits;
  for (int x : {20, 24, 28, 32, 40, 50, 60, 70, 80, 90, 100, 110, 120, 130, 134, 138, 142})
    hits.push_back(RawHit{Box{double(x), 50, 60, 40}, 1, 0});
  return hits;
}

GroupParams depthLinked(double relative, double metres) {
  GroupParams p;
  p.minNeighbors = 3;
  p.depthLink = true;
  p.depthRelative = relative;
  p.depthMetres = metres;
  return p;
}

}  // namespace

// Two adjacent objects at 10 m and 20 m: the edge rule chains all 17 windows into one box at x
// round(1368 / 17) = 80 that lies between them; linked by depth they stay two groups, x 20..60
// (7 windows, mean 254 / 7 = 36.3 -> 36) and x 70..142 (10 windows, mean 111.4 -> 111).
TEST(Grouping, DepthLinkKeepsWindowsAtDifferentDepthsApart) {
  const LayerStack stack = twoDepths(10, 20);
  const std::vector<RawHit> hits = chainAcrossTwoDepths();
  const auto old = groupHits(hits, GroupParams{}, "car", stack);
  ASSERT_EQ(old.size(), 1u);
  EXPECT_EQ(old[0].box, (Box{80, 50, 60, 40}));
  EXPECT_EQ(old[0].score, 17);
  std::vector<HitFate> fates;
  const auto d = groupHits(hits, depthLinked(0.1, 0), "car", stack, &fates);
  ASSERT_EQ(d.size(), 2u);
  EXPECT_EQ(d[0].box, (Box{36, 50, 60, 40}));
  EXPECT_EQ(d[0].score, 7);
  EXPECT_EQ(d[1].box, (Box{111, 50, 60, 40}));
  EXPECT_EQ(d[1].score, 10);
  EXPECT_EQ(fates[6].detection, 0);  // x 60: core columns 75..105, 25 of 31 at 10 m
  EXPECT_EQ(fates[7].detection, 1);  // x 70: 15 of 31 at 10 m, so the median is 20 m
  // The tolerance decides: 10 m apart is within 100 % of 10 m, or 10 m; not within 9.9 m.
  EXPECT_EQ(groupHits(hits, depthLinked(1.0, 0), "car", stack).size(), 1u);
  EXPECT_EQ(groupHits(hits, depthLinked(0, 10), "car", stack).size(), 1u);
  EXPECT_EQ(groupHits(hits, depthLinked(0, 9.9), "car", stack).size(), 2u);
  EXPECT_EQ(groupHits(hits, depthLinked(0.5, 4.9), "car", stack).size(), 2u);  // 5 + 4.9 < 10
}

// Same depth everywhere, no distance layer, or no valid laser cell: the edge rule alone.
TEST(Grouping, DepthLinkWithoutDepthDifferenceOrLaserIsTheEdgeRule) {
  const std::vector<RawHit> hits = chainAcrossTwoDepths();
  const auto expected = groupHits(hits, GroupParams{}, "car", twoDepths(10, 20));
  LayerStack noMask = twoDepths(0, 0);  // 0 m = not measured
  LayerStack masked = twoDepths(10, 20);
  masked.find(layer::kDistance)->valid = cv::Mat::zeros(200, 400, CV_8U);
  for (const LayerStack& stack : {twoDepths(15, 15), LayerStack(400, 200), noMask, masked}) {
    const auto d = groupHits(hits, depthLinked(0.1, 0), "car", stack);
    ASSERT_EQ(d.size(), expected.size());
    EXPECT_EQ(d[0].box, expected[0].box);
    EXPECT_EQ(d[0].score, expected[0].score);
  }
  // Too few valid cells (depthMinCells) count as none: only two columns measured per window core.
  LayerStack sparse(400, 200);
  cv::Mat1f d(200, 400, 0.f);
  d(cv::Rect(0, 0, 100, 200)).setTo(10.f);
  d(cv::Rect(100, 0, 300, 200)).setTo(20.f);
  cv::Mat mask = cv::Mat::zeros(200, 400, CV_8U);
  mask(cv::Rect(0, 70, 400, 1)).setTo(1);  // one band row: 31 cells per core
  sparse.set(Layer{std::string(layer::kDistance), d, mask});
  GroupParams p = depthLinked(0.1, 0);
  EXPECT_EQ(groupHits(hits, p, "car", sparse).size(), 2u);
  p.depthMinCells = 32;
  EXPECT_EQ(groupHits(hits, p, "car", sparse).size(), 1u);
}

// Random hits on a random depth layer: off, the rule is cv::groupRectangles' whatever the laser
// says; on, its groups only split the edge rule's (no hit's group grows).
TEST(Grouping, DepthLinkOnlySplitsTheEdgeRulesGroups) {
  std::mt19937 rng(5);
  int split = 0;
  for (unsigned seed = 1; seed <= 30; ++seed) {
    const auto hits = randomHits(seed, 3 + int(seed % 12));
    LayerStack stack(640, 480);
    cv::Mat1f d(120, 160);
    cv::randu(d, cv::Scalar(-5.f), cv::Scalar(40.f));  // below 0: not measured
    stack.set(Layer{std::string(layer::kDistance), d, {}});
    std::vector<cv::Rect> rects;
    for (const RawHit& h : hits) rects.emplace_back(int(h.box.x), int(h.box.y), int(h.box.w), int(h.box.h));
    std::vector<int> weights;
    cv::groupRectangles(rects, weights, 1, 0.2);
    GroupParams off;
    off.minNeighbors = 1;
    off.depthRelative = 0.01;  // ignored while depthLink is false
    const auto o = groupHits(hits, off, "car", stack);
    ASSERT_EQ(o.size(), rects.size()) << "seed " << seed;
    for (std::size_t i = 0; i < rects.size(); ++i)
      EXPECT_EQ(o[i].box, (Box{double(rects[i].x), double(rects[i].y), double(rects[i].width), double(rects[i].height)}));
    std::vector<HitFate> fOff, fOn;
    groupHits(hits, off, "car", stack, &fOff);
    GroupParams on = off;
    on.depthLink = true;
    on.depthRelative = double(rng() % 30) / 100.0;
    groupHits(hits, on, "car", stack, &fOn);
    for (std::size_t i = 0; i < hits.size(); ++i) {
      EXPECT_LE(fOn[i].groupSize, fOff[i].groupSize) << "seed " << seed << " hit " << i;
      split += fOn[i].groupSize < fOff[i].groupSize;
    }
  }
  EXPECT_GT(split, 0);  // the random depths did split some groups
}

TEST(CvIntegrals, SumSquaredAndTiltedEqualCvIntegral) {
  for (const cv::Size size : {cv::Size(1, 1), cv::Size(7, 3), cv::Size(31, 47), cv::Size(640, 480)}) {
    cv::Mat img(size, CV_8U);
    cv::randu(img, 0, 256);
    cv::Mat sum, sq, tilted;
    cv::integral(img, sum, sq, tilted, CV_32S, CV_32S);
    CvIntegrals mine;
    integrateCv(img, true, mine);
    int bad = 0;
    for (int y = 0; y <= size.height; ++y)
      for (int x = 0; x <= size.width; ++x) {
        const std::size_t i = std::size_t(y) * std::size_t(size.width + 1) + std::size_t(x);
        bad += mine.sum[i] != sum.at<int>(y, x);
        bad += int(mine.sqsum[i]) != sq.at<int>(y, x);  // both wrap modulo 2^32
        bad += mine.tilted[i] != tilted.at<int>(y, x);
      }
    EXPECT_EQ(bad, 0) << size;
  }
}
