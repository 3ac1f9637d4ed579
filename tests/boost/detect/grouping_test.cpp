// SPDX-License-Identifier: Apache-2.0
// Grouping against its peer (cv::groupRectangles on the same rectangles); and the
// integral images of the OpenCV path against cv::integral.

#include "fusedet/boost/grouping.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>
#include <random>

#include "../../../boost/detect/src/opencv_pyramid.h"

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
