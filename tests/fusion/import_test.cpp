// SPDX-License-Identifier: Apache-2.0
// KITTI import end to end (fuse -> data set -> read back), the detections file, the mosaic.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <random>

#include "fusedet/fusion/datasets/kitti_import.h"
#include "fusedet/fusion/drawing/detections_file.h"
#include "fusedet/fusion/drawing/mosaic.h"

namespace fs = std::filesystem;
using namespace fusedet;
using namespace fusedet::fusion;

namespace {
const fs::path kSample = fs::path(FUSEDET_DATA_DIR) / "kitti_object_sample";
}

TEST(KittiImport, WritesEveryFrameAndReadsBackWhatFusionBuilt) {
  const fs::path out = fs::temp_directory_path() / ("fusedet_import_test_" + std::to_string(::getpid()));
  fs::remove_all(out);
  KittiImportOptions options;
  const auto stats = importKitti(kSample, "sample", out, options);
  EXPECT_EQ(stats.frames, 3u);
  EXPECT_EQ(listDataset(out), (std::vector<std::string>{"sample/000000", "sample/000001", "sample/000002"}));
  const KittiFrame f = readKittiFrame(kSample, "000001");
  const DatasetItem fused = fuseKittiFrame(f, "sample", options.projection);
  const DatasetItem back = readDatasetItem(out, "sample/000001");
  EXPECT_EQ(back.group, "sample");
  EXPECT_EQ(back.stack.id, 1u);
  EXPECT_EQ(back.stack.names(), (std::vector<std::string>{"red", "green", "blue", "intensity", "hue", "distance", "remission"}));
  EXPECT_EQ(back.stack.width(), f.image.cols);
  EXPECT_EQ(back.stack.at("distance").width(), (f.image.cols + 1) / 2);
  EXPECT_EQ(cv::norm(back.stack.at("red").data, fused.stack.at("red").data, cv::NORM_INF), 0);
  EXPECT_EQ(cv::norm(back.stack.at("distance").valid, fused.stack.at("distance").valid, cv::NORM_INF), 0);
  EXPECT_LE(cv::norm(back.stack.at("distance").data, fused.stack.at("distance").data, cv::NORM_INF), 0.001 + 1e-5);
  EXPECT_LE(cv::norm(back.stack.at("hue").data, fused.stack.at("hue").data, cv::NORM_INF), 0.003);
  // Labels as the KITTI reader maps them: DontCare etc. are ignore regions, classes mapped.
  ASSERT_EQ(back.labels.size(), f.labels.size());
  for (std::size_t i = 0; i < f.labels.size(); ++i) {
    EXPECT_EQ(back.labels[i].className, f.labels[i].className);
    EXPECT_EQ(back.labels[i].ignore, f.labels[i].ignore);
    EXPECT_EQ(back.labels[i].box, f.labels[i].box);
  }
  fs::remove_all(out);
}

TEST(DetectionsFile, ParsesTheDocumentedFormatStrictly) {
  const auto d = parseDetectionsJson(R"({"detections":[{"class":"car","score":3.5,"x":1,"y":2,"w":30,"h":40,"extra":1}]})");
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0].className, "car");
  EXPECT_EQ(d[0].score, 3.5);
  EXPECT_EQ(d[0].box, (Box{1, 2, 30, 40}));
  EXPECT_TRUE(parseDetectionsJson(R"({"detections":[]})").empty());
  const auto errorOf = [](const std::string& text) {
    try {
      (void)parseDetectionsJson(text, "d.json");
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(errorOf(R"({"detections":[{"class":"car","score":1,"x":1,"y":2,"w":-3,"h":4}]})").find("detections[0]"), std::string::npos);
  EXPECT_NE(errorOf(R"({"detections":[{"class":"car","score":"high","x":1,"y":2,"w":3,"h":4}]})").find("score"), std::string::npos);
  EXPECT_NE(errorOf(R"({"dets":[]})").find("d.json"), std::string::npos);
  EXPECT_NE(errorOf(R"({"detections":[)").find("not valid JSON"), std::string::npos);
  EXPECT_THROW((void)readDetectionsFile("/nonexistent/dets.json"), std::runtime_error);
  // Fuzz: mutated documents are parsed or rejected, never crash.
  const std::string seed = R"({"detections":[{"class":"car","score":3.5,"x":1,"y":2,"w":30,"h":40},{"class":"bike","score":-1,"x":0,"y":0,"w":0,"h":0}]})";
  std::mt19937 rng(3);
  for (int i = 0; i < 500; ++i) {
    std::string s = seed;
    for (int k = 0; k < 1 + static_cast<int>(rng() % 4); ++k) s[rng() % s.size()] = static_cast<char>(32 + rng() % 95);
    try {
      (void)parseDetectionsJson(s);
    } catch (const std::runtime_error&) {
    }
  }
}

TEST(Mosaic, TilesEveryLayerAndDrawsBoxesWhereTheyAre) {
  LayerStack s(100, 50);
  s.set(Layer{"red", cv::Mat(50, 100, CV_8UC1, cv::Scalar(10)), {}});
  s.set(Layer{"green", cv::Mat(50, 100, CV_8UC1, cv::Scalar(10)), {}});
  s.set(Layer{"blue", cv::Mat(50, 100, CV_8UC1, cv::Scalar(10)), {}});
  cv::Mat d(25, 50, CV_32FC1, cv::Scalar(5)), m(25, 50, CV_8UC1, cv::Scalar(255));
  m(cv::Rect(0, 0, 10, 10)).setTo(0);
  s.set(Layer{"distance", d, m});
  Detection det;
  det.className = "car";
  det.score = 1;
  det.box = Box{60, 20, 20, 20};
  MosaicOptions o;
  o.columns = 2;
  const cv::Mat img = renderMosaic(s, {Label{"person", "Pedestrian", Box{10, 10, 20, 30}, 0, 0, false}}, {det}, o);
  // colour + 4 layers = 5 tiles in 2 columns -> 3 rows of (50 + caption 24) px.
  EXPECT_EQ(img.cols, 200);
  EXPECT_EQ(img.rows, 3 * 74);
  // Detection edge at x = 60 of the first tile: pure red; label edge at x = 10: green.
  EXPECT_EQ(img.at<cv::Vec3b>(24 + 30, 60), cv::Vec3b(0, 0, 255));
  EXPECT_EQ(img.at<cv::Vec3b>(24 + 25, 10), cv::Vec3b(0, 220, 0));
  // Invalid laser cells are black (distance tile: row 2, column 0; cell (2,2) -> pixel (4,4)).
  EXPECT_EQ(img.at<cv::Vec3b>(2 * 74 + 24 + 4, 4 + 0), cv::Vec3b(0, 0, 0));
  EXPECT_THROW((void)renderMosaic(LayerStack{}, {}, {}), std::invalid_argument);
}
