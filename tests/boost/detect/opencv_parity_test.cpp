// SPDX-License-Identifier: Apache-2.0
// Parity with cv::CascadeClassifier (the peer): nine cascades on real photos (opencv-doc's
// examples) and KITTI frames. Per image, our raw accepted windows must be exactly OpenCV's raw
// candidates (minNeighbors 0) as sets - not a share of all windows scanned, which a scanner that
// accepted nothing would nearly meet - and our grouped detections (minNeighbors 3) exactly
// cv::groupRectangles' of OpenCV's candidates, on every image, also where OpenCV finds none.
// Prints the figures per image.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>
#include <set>
#include <tuple>

#include "fusedet/boost/grouping.h"
#include "fusedet/boost/opencv_cascade.h"

using namespace fusedet;
using namespace fusedet::boosting;
namespace fs = std::filesystem;

namespace {

const fs::path kCascades = "/usr/share/opencv4/haarcascades";
const fs::path kPhotos = "/usr/share/doc/opencv-doc/examples/data";
const fs::path kData = FUSEDET_DATA_DIR;

std::vector<fs::path> images() {
  return {kPhotos / "messi5.jpg", kPhotos / "baboon.jpg", kPhotos / "home.jpg", kPhotos / "squirrel_cls.jpg",
          kPhotos / "building.jpg", kData / "kitti" / "image_2" / "000000.png",
          kData / "kitti_0009" / "image_2" / "000010.png"};
}

using RectKey = std::tuple<int, int, int, int>;

struct Totals {
  std::size_t windows = 0, disagreements = 0, ourHits = 0, cvHits = 0, groupsCv = 0, groupsMatched = 0,
              groupsOurs = 0, imagesWithoutCvGroups = 0;
};


Totals runCascade(const std::string& name, bool printEach) {
  Totals t;
  const fs::path file = kCascades / name;
  cv::CascadeClassifier cv;
  EXPECT_TRUE(cv.load(file.string())) << file;
  const Detector det(loadOpenCvCascade(file));
  for (const fs::path& img : images()) {
    const cv::Mat bgr = cv::imread(img.string(), cv::IMREAD_COLOR);
    EXPECT_FALSE(bgr.empty()) << "cannot read " << img;
    if (bgr.empty()) continue;
    cv::Mat gray;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    std::vector<cv::Rect> raw;
    cv.detectMultiScale(gray, raw, 1.1, 0, 0, cv::Size());
    LayerStack stack(gray.cols, gray.rows);
    stack.set(Layer{"intensity", gray, {}});
    ScanParams p;
    p.scaleFactor = 1.1;
    ScanStats stats;
    const std::vector<RawHit> hits = det.scan(stack, p, &stats);
    std::multiset<RectKey> theirs, ours;
    for (const cv::Rect& r : raw) theirs.insert({r.x, r.y, r.width, r.height});
    for (const RawHit& h : hits) ours.insert({int(h.box.x), int(h.box.y), int(h.box.w), int(h.box.h)});
    std::vector<RectKey> diff;
    std::set_symmetric_difference(ours.begin(), ours.end(), theirs.begin(), theirs.end(), std::back_inserter(diff));
    // Grouped: OpenCV's own grouping of its candidates vs ours of our hits, rectangle for rectangle.
    std::vector<cv::Rect> cvGrouped = raw;
    cv::groupRectangles(cvGrouped, 3, 0.2);
    GroupParams g;
    g.minNeighbors = 3;
    const auto mine = groupHits(hits, g, "x", stack);
    std::multiset<RectKey> cvGroups, ourGroups;
    for (const cv::Rect& r : cvGrouped) cvGroups.insert({r.x, r.y, r.width, r.height});
    for (const Detection& d : mine) ourGroups.insert({int(d.box.x), int(d.box.y), int(d.box.w), int(d.box.h)});
    std::size_t matched = 0;
    for (const RectKey& k : cvGroups) matched += ourGroups.count(k) ? 1 : 0;
    const std::string where = name + " on " + img.filename().string();
    EXPECT_EQ(ours, theirs) << where << ": raw accepted windows differ in " << diff.size() << " windows";
    EXPECT_EQ(ourGroups, cvGroups) << where << ": grouped detections differ (ours " << mine.size() << ", OpenCV "
                                   << cvGrouped.size() << ")";
    if (cvGrouped.empty()) ++t.imagesWithoutCvGroups;
    t.windows += stats.windows;
    t.disagreements += diff.size();
    t.ourHits += hits.size();
    t.cvHits += raw.size();
    t.groupsCv += cvGrouped.size();
    t.groupsOurs += mine.size();
    t.groupsMatched += matched;
    if (printEach)
      std::printf("parity %-36s %-18s windows %8zu  hits ours %5zu opencv %5zu  differ %3zu  groups %2zu/%2zu matched %2zu\n",
                  name.c_str(), img.filename().c_str(), stats.windows, hits.size(), raw.size(), diff.size(), mine.size(),
                  cvGrouped.size(), matched);
  }
  return t;
}

void checkParity(const std::string& name) {
  const Totals t = runCascade(name, true);
  std::printf("parity %s: %zu windows, raw hits ours %zu opencv %zu (%zu differ), grouped ours %zu opencv %zu "
              "(%zu identical; %zu images where OpenCV groups none)\n",
              name.c_str(), t.windows, t.ourHits, t.cvHits, t.disagreements, t.groupsOurs, t.groupsCv, t.groupsMatched,
              t.imagesWithoutCvGroups);
  EXPECT_GT(t.windows, 100000u);
  EXPECT_GT(t.cvHits, 0u) << "the photos should give OpenCV some candidates";
  EXPECT_EQ(t.disagreements, 0u);
  EXPECT_EQ(t.groupsMatched, t.groupsCv);
  EXPECT_EQ(t.groupsOurs, t.groupsCv);
}

}  // namespace

// The AVX2 path and the one-window reference path report the same hits and do the same work.
TEST(OpenCvParity, VectorPathEqualsReferencePath) {
  for (const char* name : {"haarcascade_frontalface_default.xml", "haarcascade_fullbody.xml", "haarcascade_eye.xml"}) {
    const Detector det(loadOpenCvCascade(kCascades / name));
    for (const fs::path& img : {images()[0], images()[5]}) {
      cv::Mat gray = cv::imread(img.string(), cv::IMREAD_GRAYSCALE);
      ASSERT_FALSE(gray.empty()) << img;
      LayerStack stack(gray.cols, gray.rows);
      stack.set(Layer{"intensity", gray, {}});
      ScanParams p;
      p.scaleFactor = 1.2;
      ScanStats a, b;
      setVectorScanEnabled(false);
      const auto ref = det.scan(stack, p, &a);
      setVectorScanEnabled(true);
      const auto vec = det.scan(stack, p, &b);
      ASSERT_EQ(ref.size(), vec.size()) << name << " " << img;
      for (std::size_t i = 0; i < ref.size(); ++i) {
        EXPECT_EQ(ref[i].box, vec[i].box);
        EXPECT_EQ(ref[i].score, vec[i].score);
      }
      EXPECT_EQ(a.windows, b.windows);
      EXPECT_EQ(a.stumps, b.stumps);
    }
  }
}

// Threads split rows; the merged output is the single-threaded one, in order and value.
TEST(OpenCvParity, MultiThreadedScanIsIdenticalToSingleThreaded) {
  const Detector det(loadOpenCvCascade(kCascades / "haarcascade_eye.xml"));
  const cv::Mat gray = cv::imread(images()[0].string(), cv::IMREAD_GRAYSCALE);
  ASSERT_FALSE(gray.empty());
  LayerStack stack(gray.cols, gray.rows);
  stack.set(Layer{"intensity", gray, {}});
  ScanParams p;
  p.threads = 1;
  const auto one = det.scan(stack, p);
  ASSERT_GT(one.size(), 5u);
  for (int threads : {0, 2, 3}) {
    p.threads = threads;
    const auto many = det.scan(stack, p);
    ASSERT_EQ(many.size(), one.size());
    for (std::size_t i = 0; i < one.size(); ++i) {
      EXPECT_EQ(many[i].box, one[i].box);
      EXPECT_EQ(many[i].score, one[i].score);
    }
  }
}

TEST(OpenCvParity, FrontalFaceDefault) { checkParity("haarcascade_frontalface_default.xml"); }
TEST(OpenCvParity, FrontalFaceAlt) { checkParity("haarcascade_frontalface_alt.xml"); }
TEST(OpenCvParity, ProfileFace) { checkParity("haarcascade_profileface.xml"); }
TEST(OpenCvParity, Eye) { checkParity("haarcascade_eye.xml"); }
TEST(OpenCvParity, FrontalCatFace) { checkParity("haarcascade_frontalcatface.xml"); }
TEST(OpenCvParity, FullBodyWithTiltedFeatures) { checkParity("haarcascade_fullbody.xml"); }
TEST(OpenCvParity, FrontalFaceAlt2Trees) { checkParity("haarcascade_frontalface_alt2.xml"); }
TEST(OpenCvParity, EyeTreeEyeglassesTiltedTrees) { checkParity("haarcascade_eye_tree_eyeglasses.xml"); }
TEST(OpenCvParity, OldFormatLicencePlate) { checkParity("haarcascade_licence_plate_rus_16stages.xml"); }
