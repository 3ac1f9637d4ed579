// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/dataset.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <random>
#include <sstream>

namespace fs = std::filesystem;
using namespace fusedet;

namespace {

fs::path freshDir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("fusedet_dataset_test_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream out;
  out << in.rdbuf();
  return out.str();
}
void spit(const fs::path& p, const std::string& s) { std::ofstream(p, std::ios::binary | std::ios::trunc) << s; }

// A stack like fusion builds: 8-bit camera layers at full size, float laser layers at half size.
DatasetItem sampleItem(const std::string& id, const std::string& group, std::uint32_t seed) {
  cv::RNG rng(seed);
  DatasetItem item;
  item.id = id;
  item.group = group;
  item.stack = LayerStack(64, 48);
  item.stack.id = seed;
  item.stack.stamp = Stamp{1'234'567'890'123 + seed};
  item.stack.source = "test/" + id;
  cv::Mat red(48, 64, CV_8UC1), wide(48, 64, CV_16UC1), hue(48, 64, CV_32FC1);
  rng.fill(red, cv::RNG::UNIFORM, 0, 256);
  rng.fill(wide, cv::RNG::UNIFORM, 0, 65536);
  rng.fill(hue, cv::RNG::UNIFORM, 0.f, 360.f);
  cv::Mat dist(24, 32, CV_32FC1), rem(24, 32, CV_32FC1), mask(24, 32, CV_8UC1);
  rng.fill(dist, cv::RNG::UNIFORM, 0.5f, 80.f);
  rng.fill(rem, cv::RNG::UNIFORM, 0.f, 1.f);
  rng.fill(mask, cv::RNG::UNIFORM, 0, 2);
  mask *= 255;
  dist.setTo(0, mask == 0);
  item.stack.set(Layer{"red", red, {}});
  item.stack.set(Layer{"wide", wide, {}});
  item.stack.set(Layer{"hue", hue, {}});
  item.stack.set(Layer{"distance", dist, mask});
  item.stack.set(Layer{"remission", rem, mask});
  item.labels.push_back(Label{"car", "Car", Box{1.5, 2.25, 30, 20}, 0.5, 1, false});
  item.labels.push_back(Label{"dontcare", "DontCare", Box{40, 10, 5, 5}, 0, -1, true});
  return item;
}

double maxAbsDiff(const cv::Mat& a, const cv::Mat& b) {
  cv::Mat a64, b64;
  a.convertTo(a64, CV_64F);
  b.convertTo(b64, CV_64F);
  return cv::norm(a64, b64, cv::NORM_INF);
}

}  // namespace

TEST(Dataset, RoundTripKeepsLayersLabelsAndMetadata) {
  const fs::path dir = freshDir("roundtrip");
  const DatasetItem in = sampleItem("drive/000001", "drive", 7);
  writeDatasetItem(dir, in);
  const DatasetItem out = readDatasetItem(dir, "drive/000001");
  EXPECT_EQ(out.id, in.id);
  EXPECT_EQ(out.group, "drive");
  EXPECT_EQ(out.stack.width(), 64);
  EXPECT_EQ(out.stack.height(), 48);
  EXPECT_EQ(out.stack.id, 7u);
  EXPECT_EQ(out.stack.stamp, in.stack.stamp);
  EXPECT_EQ(out.stack.source, in.stack.source);
  EXPECT_EQ(out.stack.names(), in.stack.names());
  // Integer layers and masks are exact.
  EXPECT_EQ(maxAbsDiff(out.stack.at("red").data, in.stack.at("red").data), 0);
  EXPECT_EQ(out.stack.at("wide").data.type(), CV_16UC1);
  EXPECT_EQ(maxAbsDiff(out.stack.at("wide").data, in.stack.at("wide").data), 0);
  EXPECT_EQ(maxAbsDiff(out.stack.at("distance").valid, in.stack.at("distance").valid), 0);
  EXPECT_FALSE(out.stack.at("hue").hasMask());
  // Float layers within half their documented quantum: 2 mm, 1/65535, 360/65536 degrees.
  EXPECT_EQ(out.stack.at("distance").data.type(), CV_32FC1);
  EXPECT_LE(maxAbsDiff(out.stack.at("distance").data, in.stack.at("distance").data), 0.001 + 1e-5);
  EXPECT_LE(maxAbsDiff(out.stack.at("remission").data, in.stack.at("remission").data), 0.5 / 65535 + 1e-6);
  EXPECT_LE(maxAbsDiff(out.stack.at("hue").data, in.stack.at("hue").data), 0.5 * 360 / 65536 + 1e-4);
  // Invalid distance cells stay exactly 0.
  cv::Mat zeroIn = in.stack.at("distance").data == 0, zeroOut = out.stack.at("distance").data == 0;
  EXPECT_EQ(cv::countNonZero(zeroIn != zeroOut), 0);
  ASSERT_EQ(out.labels.size(), 2u);
  EXPECT_EQ(out.labels[0].className, "car");
  EXPECT_EQ(out.labels[0].sourceClass, "Car");
  EXPECT_EQ(out.labels[0].box, (Box{1.5, 2.25, 30, 20}));
  EXPECT_EQ(out.labels[0].truncation, 0.5);
  EXPECT_EQ(out.labels[0].occlusion, 1);
  EXPECT_TRUE(out.labels[1].ignore);
  fs::remove_all(dir);
}

TEST(Dataset, FilesOpenInCommonToolsAsDocumented) {
  const fs::path dir = freshDir("plain");
  const DatasetItem in = sampleItem("a", "g", 3);
  writeDatasetItem(dir, in);
  // A plain PNG reader sees the documented encoding: distance in 2 mm steps, mask 0/255.
  const cv::Mat d = cv::imread((dir / "items/a/distance.png").string(), cv::IMREAD_UNCHANGED);
  ASSERT_EQ(d.type(), CV_16UC1);
  const cv::Mat& src = in.stack.at("distance").data;
  for (int y = 0; y < d.rows; y += 5)
    for (int x = 0; x < d.cols; x += 3)
      EXPECT_EQ(d.at<std::uint16_t>(y, x), static_cast<int>(std::lround(src.at<float>(y, x) / 0.002)));
  const cv::Mat m = cv::imread((dir / "items/a/distance.valid.png").string(), cv::IMREAD_UNCHANGED);
  EXPECT_EQ(m.type(), CV_8UC1);
  EXPECT_EQ(cv::countNonZero((m != 0) & (m != 255)), 0);
  const auto j = nlohmann::json::parse(slurp(dir / "items/a/item.json"));
  EXPECT_EQ(j["format"], "fusedet-item");
  EXPECT_EQ(j["layers"][3]["name"], "distance");
  EXPECT_DOUBLE_EQ(j["layers"][3]["scale"].get<double>(), 0.002);
  EXPECT_EQ(j["layers"][3]["mask"], "distance.valid.png");
  fs::remove_all(dir);
}

TEST(Dataset, FarRangesWidenTheStepAndSayItInTheSidecar) {
  const fs::path dir = freshDir("far");
  DatasetItem in = sampleItem("far", "g", 5);
  cv::Mat d = in.stack.at("distance").data.clone();
  d.at<float>(0, 0) = 200.f;  // beyond 65535 * 2 mm
  d.at<float>(1, 1) = -3.f;   // and a negative value (not a distance, but any float layer may)
  in.stack.set(Layer{"distance", d, in.stack.at("distance").valid});
  writeDatasetItem(dir, in);
  const auto j = nlohmann::json::parse(slurp(dir / "items/far/item.json"));
  const double scale = j["layers"][3]["scale"].get<double>();
  EXPECT_GT(scale, 0.002);
  const DatasetItem out = readDatasetItem(dir, "far");
  EXPECT_LE(maxAbsDiff(out.stack.at("distance").data, d), scale / 2 + 1e-5);
  EXPECT_NEAR(out.stack.at("distance").data.at<float>(0, 0), 200.f, scale);
  EXPECT_NEAR(out.stack.at("distance").data.at<float>(1, 1), -3.f, scale);
  fs::remove_all(dir);
}

TEST(Dataset, ManifestKeepsWriteOrderAndReplaces) {
  const fs::path dir = freshDir("manifest");
  writeDatasetItem(dir, sampleItem("b/000003", "b", 1));
  writeDatasetItem(dir, sampleItem("a/000000", "a", 2));
  writeDatasetItem(dir, sampleItem("b/000001", "b", 3));
  DatasetItem replaced = sampleItem("a/000000", "a2", 4);
  replaced.stack = LayerStack(64, 48);
  replaced.stack.set(Layer{"intensity", cv::Mat(48, 64, CV_8UC1, cv::Scalar(9)), {}});
  writeDatasetItem(dir, replaced);
  EXPECT_EQ(listDataset(dir), (std::vector<std::string>{"b/000003", "a/000000", "b/000001"}));
  const auto m = readDatasetManifest(dir);
  EXPECT_EQ(m[1].group, "a2");
  const DatasetItem r = readDatasetItem(dir, "a/000000");
  EXPECT_EQ(r.stack.names(), (std::vector<std::string>{"intensity"}));
  EXPECT_FALSE(fs::exists(dir / "items/a/000000/red.png"));  // stale layer files removed
  fs::remove_all(dir);
}

TEST(Dataset, ReadsOnlySelectedLayersInTheRequestedOrder) {
  const fs::path dir = freshDir("select");
  writeDatasetItem(dir, sampleItem("x", "g", 9));
  const DatasetItem s = readDatasetItem(dir, "x", {"remission", "red", "remission"});
  EXPECT_EQ(s.stack.names(), (std::vector<std::string>{"remission", "red"}));
  EXPECT_EQ(s.labels.size(), 2u);
  const DatasetItem l = readDatasetItemLabels(dir, "x");
  EXPECT_EQ(l.stack.size(), 0u);
  EXPECT_EQ(l.stack.width(), 64);
  EXPECT_EQ(l.labels.size(), 2u);
  try {
    (void)readDatasetItem(dir, "x", {"red", "sonar"});
    FAIL();
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("sonar"), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("item.json"), std::string::npos);
  }
  fs::remove_all(dir);
}

TEST(Dataset, KeepsTheNetworkOfNeuralLayers) {
  const fs::path dir = freshDir("network");
  DatasetItem item = sampleItem("n", "g", 3);
  writeDatasetItem(dir, item);
  EXPECT_EQ(slurp(dir / "items" / "n" / "item.json").find("\"network\""), std::string::npos);  // none: no key
  item.stack.network = NetworkRecord{"yolov5-onnx", 832, 256, {"y.onnx"}, {std::string(64, 'c')}};
  writeDatasetItem(dir, item);
  EXPECT_EQ(readDatasetItem(dir, "n").stack.network, item.stack.network);
  EXPECT_EQ(readDatasetItem(dir, "n", {"red"}).stack.network, item.stack.network);
  std::string json = slurp(dir / "items" / "n" / "item.json");
  const std::string digest = "sha256:" + std::string(64, 'c');
  json.replace(json.find(digest), digest.size(), "sha256:cc");
  spit(dir / "items" / "n" / "item.json", json);
  try {
    (void)readDatasetItem(dir, "n");
    FAIL();
  } catch (const DatasetError& e) {
    EXPECT_NE(std::string(e.what()).find("item.json"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("sha256:cc"), std::string::npos) << e.what();
  }
  fs::remove_all(dir);
}

TEST(Dataset, RejectsBadInputNamingFileAndProblem) {
  const fs::path dir = freshDir("bad");
  EXPECT_THROW(listDataset(dir), DatasetError);  // no manifest
  DatasetItem bad = sampleItem("../escape", "g", 1);
  EXPECT_THROW(writeDatasetItem(dir, bad), DatasetError);
  bad = sampleItem("nan", "g", 1);
  cv::Mat d = bad.stack.at("distance").data.clone();
  d.at<float>(2, 2) = NAN;
  bad.stack.set(Layer{"distance", d, {}});
  EXPECT_THROW(writeDatasetItem(dir, bad), DatasetError);

  writeDatasetItem(dir, sampleItem("ok", "g", 1));
  const fs::path item = dir / "items/ok";
  const std::string json = slurp(item / "item.json"), png = slurp(item / "distance.png");
  auto expectError = [&](const std::string& fileNeedle, const std::string& problemNeedle) {
    try {
      (void)readDatasetItem(dir, "ok");
      ADD_FAILURE() << "no error for " << problemNeedle;
    } catch (const DatasetError& e) {
      const std::string msg = e.what();
      EXPECT_NE(msg.find(fileNeedle), std::string::npos) << msg;
      EXPECT_NE(msg.find(problemNeedle), std::string::npos) << msg;
    }
  };
  spit(item / "distance.png", png.substr(0, png.size() / 2));
  expectError("distance.png", "corrupt or truncated");
  spit(item / "distance.png", "hello");
  expectError("distance.png", "not a PNG");
  cv::imwrite((item / "distance.png").string(), cv::Mat(3, 3, CV_16UC1, cv::Scalar(1)));
  expectError("distance.png", "3x3");
  fs::remove(item / "distance.png");
  expectError("distance.png", "cannot open");
  spit(item / "distance.png", png);
  spit(item / "item.json", json.substr(0, json.size() - 20));
  expectError("item.json", "not valid JSON");
  spit(item / "item.json", std::string(json).replace(json.find("\"version\": 1"), 12, "\"version\": 7"));
  expectError("item.json", "version 7");
  spit(item / "item.json", std::string(json).replace(json.find("\"f32\""), 5, "\"f64\""));
  expectError("item.json", "f64");
  spit(item / "item.json", json);
  EXPECT_NO_THROW((void)readDatasetItem(dir, "ok"));
  EXPECT_THROW((void)readDatasetItem(dir, "missing"), DatasetError);
  fs::remove_all(dir);
}

// Random byte flips, truncations and insertions in every file of an item: each read either
// succeeds or throws DatasetError, never crashes, hangs or throws anything else.
TEST(Dataset, FuzzedFilesNeverCrashTheReader) {
  const fs::path dir = freshDir("fuzz");
  writeDatasetItem(dir, sampleItem("f", "g", 11));
  const fs::path item = dir / "items/f";
  const std::vector<fs::path> files{item / "item.json", item / "red.png", item / "distance.png",
                                    item / "distance.valid.png", dir / "dataset.json"};
  std::mt19937 rng(1234);
  int errors = 0, reads = 0;
  for (const fs::path& file : files) {
    const std::string original = slurp(file);
    for (int iter = 0; iter < 120; ++iter) {
      std::string s = original;
      const int kind = static_cast<int>(rng() % 4);
      const auto pos = [&] { return rng() % std::max<std::size_t>(s.size(), 1); };
      if (kind == 0) {
        for (int k = 0; k < 1 + static_cast<int>(rng() % 8); ++k) s[pos()] = static_cast<char>(rng());
      } else if (kind == 1) {
        s.resize(pos());
      } else if (kind == 2) {
        s.insert(pos(), std::string(1 + rng() % 16, static_cast<char>(rng())));
      } else {
        const std::size_t p = pos();
        s.erase(p, 1 + rng() % 32);
      }
      spit(file, s);
      try {
        if (file.filename() == "dataset.json")
          (void)listDataset(dir);
        else
          (void)readDatasetItem(dir, "f");
        ++reads;
      } catch (const DatasetError&) {
        ++errors;
      }
    }
    spit(file, original);
  }
  EXPECT_GT(errors, 300);  // most mutations are caught (PNG CRCs, JSON syntax, strict fields)
  EXPECT_EQ(errors + reads, 600);
  fs::remove_all(dir);
}

TEST(Dataset, IdSegmentsAreFolderNamesAndFileStemsBecomeOne) {
  for (const char* ok : {"kitti", "drive_0005", "2011-09-26", "a.b", "..a", "Z9"}) EXPECT_TRUE(isIdSegment(ok)) << ok;
  for (const char* bad : {"", ".", "..", "a/b", "a b", "\xc3\xa9t\xc3\xa9", "a\\b", "x:y"}) EXPECT_FALSE(isIdSegment(bad)) << bad;
  EXPECT_EQ(toIdSegment("run 3 (robot:7)", "log"), "run_3__robot_7_");
  EXPECT_EQ(toIdSegment("2026-12-02.front", "log"), "2026-12-02.front");
  EXPECT_EQ(toIdSegment("", "log"), "log");
  EXPECT_EQ(toIdSegment("..", "log"), "log");
  EXPECT_EQ(toIdSegment("/", "log"), "_");
  // What toIdSegment makes is always an id the data set takes.
  const fs::path dir = freshDir("idseg");
  writeDatasetItem(dir, sampleItem(toIdSegment("caf\xc3\xa9 log", "log") + "/000001", "g", 1));
  EXPECT_EQ(listDataset(dir), std::vector<std::string>{"caf___log/000001"});
  fs::remove_all(dir);
}
