// SPDX-License-Identifier: Apache-2.0
// `fusedet demo` and `fusedet detect` detect as fusedetd does: car grouped with its own settings
// (fusedet/boost/class_detection.h) on a real KITTI frame. The expected detections are computed here with
// detectPerClass() and a car grouping built in this test from classDetectionDefault("car") - not
// with the classGroupings() the commands use - and the frame is one where car's settings change
// car's detections, so a command that grouped car with the general settings fails.

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/core/dataset.h"
#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::boosting {
namespace {
namespace fs = std::filesystem;

const fs::path kData = FUSEDET_DATA_DIR;
const fs::path kModels = fs::path(FUSEDET_SOURCE_DIR) / "models";
const fs::path kFusedet = fs::path(FUSEDET_BINARY_DIR) / "tools" / "fusedet";
// A frame where both of car's settings matter: 16 neighbours drop a detection that 3 keep, and the
// laser extent moves a box.
const std::string kFrame = "000060";

struct CommandRun {
  int status = -1;
  std::string out;
};

CommandRun run(const std::string& args) {
  CommandRun r;
  FILE* p = popen((kFusedet.string() + " " + args + " 2>&1").c_str(), "r");
  if (!p) return r;
  char buf[4096];
  while (std::fgets(buf, sizeof buf, p)) r.out += buf;
  r.status = pclose(p);
  return r;
}

std::vector<Detection> carsOf(const std::vector<Detection>& all) {
  std::vector<Detection> out;
  for (const Detection& d : all)
    if (d.className == "car") out.push_back(d);
  return out;
}

// Boxes equal to `tolerance` pixels (the demo prints one decimal), scores to `scoreTolerance`.
void expectSameDetections(const std::vector<Detection>& got, const std::vector<Detection>& want, double tolerance,
                          double scoreTolerance, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].className, want[i].className) << what << " #" << i;
    EXPECT_NEAR(got[i].score, want[i].score, scoreTolerance) << what << " #" << i;
    EXPECT_NEAR(got[i].box.x, want[i].box.x, tolerance) << what << " #" << i;
    EXPECT_NEAR(got[i].box.y, want[i].box.y, tolerance) << what << " #" << i;
    EXPECT_NEAR(got[i].box.w, want[i].box.w, tolerance) << what << " #" << i;
    EXPECT_NEAR(got[i].box.h, want[i].box.h, tolerance) << what << " #" << i;
  }
}

bool sameBoxes(const std::vector<Detection>& a, const std::vector<Detection>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (std::abs(a[i].box.x - b[i].box.x) > 0.5 || std::abs(a[i].box.w - b[i].box.w) > 0.5 ||
        std::abs(a[i].box.y - b[i].box.y) > 0.5 || std::abs(a[i].box.h - b[i].box.h) > 0.5)
      return false;
  return true;
}

MultiDetector bundledModels() {
  std::vector<Cascade> models;
  for (const char* name : {"bike", "car", "person"})  // the demo's order: its files sorted by name
    models.push_back(loadModel(kModels / (std::string(name) + ".json")));
  return MultiDetector(std::move(models));
}

// Car's grouping as the library states it, built here field by field (not by classGroupings()).
std::vector<ClassGrouping> carsOwn() {
  const std::optional<ClassDetection> car = classDetectionDefault("car");
  if (!car) return {};
  return {{"car", car->minNeighbors, car->laserExtent}};
}

std::vector<Detection> parseDemoCars(const std::string& out) {
  static const std::regex line(
      R"(\n  car +score= *([-0-9.]+) box x=([-0-9.]+) y=([-0-9.]+) w=([-0-9.]+) h=([-0-9.]+))");
  std::vector<Detection> cars;
  for (auto it = std::sregex_iterator(out.begin(), out.end(), line); it != std::sregex_iterator(); ++it) {
    Detection d;
    d.className = "car";
    d.score = std::stod((*it)[1]);
    d.box = {std::stod((*it)[2]), std::stod((*it)[3]), std::stod((*it)[4]), std::stod((*it)[5])};
    cars.push_back(d);
  }
  return cars;
}

std::vector<Detection> readJsonDetections(const fs::path& file) {
  std::ifstream in(file);
  const nlohmann::json j = nlohmann::json::parse(in);
  std::vector<Detection> out;
  for (const auto& e : j.at("detections")) {
    Detection d;
    d.className = e.at("class");
    d.score = e.at("score");
    d.box = {e.at("x"), e.at("y"), e.at("w"), e.at("h")};
    out.push_back(d);
  }
  return out;
}

TEST(ClassDetectionCommands, DemoGroupsCarWithItsOwnSettings) {
  ASSERT_TRUE(fs::exists(kFusedet)) << kFusedet;
  const fusion::KittiFrame f = fusion::readKittiFrame(kData / "kitti", kFrame);
  const LayerStack stack = fusion::kittiFuser(f.calib, f.image.cols, f.image.rows).fuse(f.image, f.points);
  const MultiDetector models = bundledModels();
  ScanParams scan;  // the demo's scan: fusedetd's defaults (1.1, step 2)
  scan.threads = 1;
  const std::vector<Detection> own = carsOf(detectPerClass(models, stack, scan, {}, {}, carsOwn()));
  const std::vector<Detection> general = carsOf(detectPerClass(models, stack, scan, {}, {}, {}));
  ASSERT_FALSE(own.empty()) << "car's own settings find no car on kitti/" << kFrame << ": pick another frame";
  ASSERT_NE(own.size(), general.size()) << "car's settings change nothing on this frame: the test could not fail";

  const CommandRun demo = run("demo --data " + kData.string() + " --frame " + kFrame + " --models " + kModels.string() +
                       " --threads 1");
  ASSERT_EQ(demo.status, 0) << demo.out;
  EXPECT_NE(demo.out.find("its own grouping: 16 neighbours, laser extent on"), std::string::npos) << demo.out;
  expectSameDetections(parseDemoCars(demo.out), own, 0.051, 0.0005, "demo");

  const CommandRun plain = run("demo --data " + kData.string() + " --frame " + kFrame + " --models " + kModels.string() +
                        " --threads 1 --no-class-detection");
  ASSERT_EQ(plain.status, 0) << plain.out;
  expectSameDetections(parseDemoCars(plain.out), general, 0.051, 0.0005, "demo --no-class-detection");
}

TEST(ClassDetectionCommands, DetectGroupsCarWithItsOwnSettingsUnlessToldOtherwise) {
  ASSERT_TRUE(fs::exists(kFusedet)) << kFusedet;
  const fs::path dir = fs::path(::testing::TempDir()) / "class_detection_commands";
  fs::remove_all(dir);
  const fusion::KittiFrame f = fusion::readKittiFrame(kData / "kitti", kFrame);
  DatasetItem item;
  item.id = "kitti/" + kFrame;
  item.group = "kitti";
  item.stack = fusion::kittiFuser(f.calib, f.image.cols, f.image.rows).fuse(f.image, f.points);
  writeDatasetItem(dir, item);
  // What detect reads: the written (quantised) stack.
  const LayerStack stack = readDatasetItem(dir, item.id).stack;
  const MultiDetector car({loadModel(kModels / "car.json")});
  ScanParams scan;
  scan.threads = 1;
  const std::vector<Detection> own = detectPerClass(car, stack, scan, {}, {}, carsOwn());
  const std::vector<Detection> general = detectPerClass(car, stack, scan, {}, {}, {});
  GroupParams three;
  three.minNeighbors = 3;
  const std::vector<ClassGrouping> carWith3{{"car", 3, carsOwn().at(0).laserExtent}};
  const std::vector<Detection> ownExtentOnly = detectPerClass(car, stack, scan, three, {}, carWith3);
  ASSERT_FALSE(own.empty());
  ASSERT_NE(own.size(), general.size()) << "car's neighbours change nothing on this frame: the test could not fail";
  ASSERT_FALSE(sameBoxes(ownExtentOnly, general)) << "car's laser extent changes nothing on this frame";

  const std::string base =
      "detect -m " + (kModels / "car.json").string() + " --stack " + dir.string() + " --threads 1 --json ";
  const CommandRun byDefault = run(base + (dir / "own.json").string());
  ASSERT_EQ(byDefault.status, 0) << byDefault.out;
  expectSameDetections(readJsonDetections(dir / "own.json"), own, 1e-9, 1e-9, "detect");

  const CommandRun plain = run(base + (dir / "general.json").string() + " --no-class-detection");
  ASSERT_EQ(plain.status, 0) << plain.out;
  expectSameDetections(readJsonDetections(dir / "general.json"), general, 1e-9, 1e-9, "detect --no-class-detection");

  // --min-neighbors given holds for every class, car included; car keeps its own laser extent.
  const CommandRun given = run(base + (dir / "three.json").string() + " --min-neighbors 3");
  ASSERT_EQ(given.status, 0) << given.out;
  expectSameDetections(readJsonDetections(dir / "three.json"), ownExtentOnly, 1e-9, 1e-9, "detect --min-neighbors 3");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace fusedet::boosting
