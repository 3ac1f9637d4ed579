// SPDX-License-Identifier: Apache-2.0
// Unit tests of the daemon's small parts: the drop-oldest queue, the meters, the request parser
// (with garbage input) and 3D localization from the distance layer.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <random>

#include "fusedet/daemon/bounded_queue.h"
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/localize.h"
#include "fusedet/daemon/protocol.h"
#include "fusedet/daemon/service.h"
#include "fusedet/daemon/stack_detector.h"
#include "fusedet/daemon/stats.h"
#include "fusedet/fusion/fuser.h"
#include "fusedet/fusion/projection.h"

using namespace fusedet;
using namespace fusedet::daemon;

TEST(BoundedQueue, DropsTheOldestAndCountsIt) {
  BoundedQueue<int> q(3);
  for (int i = 0; i < 5; ++i) q.push(i);
  const auto c = q.counters();
  EXPECT_EQ(c.pushed, 5u);
  EXPECT_EQ(c.dropped, 2u);
  EXPECT_EQ(c.depth, 3u);
  EXPECT_EQ(q.pop(std::chrono::milliseconds(0)), 2);  // 0 and 1 were dropped
  q.close();
  EXPECT_FALSE(q.push(9));
  EXPECT_EQ(q.pop(std::chrono::milliseconds(0)), 3);
  EXPECT_EQ(q.pop(std::chrono::milliseconds(0)), 4);
  EXPECT_EQ(q.pop(std::chrono::milliseconds(50)), std::nullopt);
}

// Issue 37: the sensor queue was bounded by count only - 512 1080p YUYV frames are 2 GB. With a
// size function it drops its oldest items also to stay within a byte budget, keeps the newest
// even alone over it, and a waiting (lossless) producer waits for half the budget.
TEST(BoundedQueue, ABytesBudgetBoundsItToo) {
  constexpr std::size_t kFrame = 1920 * 1080 * 2;
  BoundedQueue<std::vector<std::uint8_t>> q(512, 4 * kFrame, [](const std::vector<std::uint8_t>& v) { return v.size(); });
  for (int i = 0; i < 10; ++i) q.push(std::vector<std::uint8_t>(kFrame, static_cast<std::uint8_t>(i)));
  auto c = q.counters();
  EXPECT_EQ(c.depth, 4u);
  EXPECT_EQ(c.dropped, 6u);
  EXPECT_EQ(c.bytes, 4 * kFrame);
  EXPECT_EQ(q.pop(std::chrono::milliseconds(0))->front(), 6);  // the oldest kept
  EXPECT_EQ(q.counters().bytes, 3 * kFrame);
  EXPECT_FALSE(q.waitForRoom(512, std::chrono::milliseconds(0)));  // 3 of 4 frames' budget used
  q.pop(std::chrono::milliseconds(0));
  EXPECT_TRUE(q.waitForRoom(512, std::chrono::milliseconds(0)));
  q.push(std::vector<std::uint8_t>(8 * kFrame));  // alone over the budget: kept, the rest dropped
  c = q.counters();
  EXPECT_EQ(c.depth, 1u);
  EXPECT_EQ(c.bytes, 8 * kFrame);
  // Small items still count against the capacity.
  BoundedQueue<std::vector<std::uint8_t>> small(3, 1 << 20, [](const std::vector<std::uint8_t>& v) { return v.size(); });
  for (int i = 0; i < 5; ++i) small.push(std::vector<std::uint8_t>(10));
  EXPECT_EQ(small.counters().depth, 3u);
  EXPECT_EQ(small.counters().bytes, 30u);
}

TEST(Stats, LatencySummaryAndRates) {
  LatencyRecorder r(10);
  for (int i = 1; i <= 20; ++i) r.add(i);  // keeps 11..20
  EXPECT_EQ(r.summary().samples, 10u);
  EXPECT_DOUBLE_EQ(r.summary().p50Ms, 15);
  EXPECT_DOUBLE_EQ(r.summary().maxMs, 20);
  RateMeter m(1'000'000'000);
  for (int i = 0; i < 10; ++i) m.tick(i * 100'000'000LL);  // 10 Hz
  EXPECT_NEAR(m.rate(950'000'000LL), 10.0, 1e-9);
  EXPECT_NEAR(m.rate(5'000'000'000LL), 0.0, 1e-9);
  EXPECT_EQ(m.total(), 10u);
}

TEST(Protocol, ParsesTheDocumentedRequests) {
  std::string err;
  auto r = parseRequest(R"({"cmd":"subscribe","classes":["car","bike"],"id":7})", err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->command, Request::Command::kSubscribe);
  EXPECT_EQ(r->classes, (std::set<std::string>{"bike", "car"}));
  EXPECT_EQ(r->id, 7);
  EXPECT_TRUE(parseRequest(R"({"cmd":"status"})", err));
  EXPECT_FALSE(parseRequest(R"({"cmd":"launch"})", err));
  EXPECT_EQ(err, "unknown cmd 'launch'");
  EXPECT_FALSE(parseRequest(R"({"cmd":"status","classes":["car"]})", err));
  EXPECT_FALSE(parseRequest(R"({"cmd":"subscribe","classes":"car"})", err));
  EXPECT_FALSE(parseRequest(R"([1,2])", err));
  EXPECT_EQ(err, "expected a JSON object");
  EXPECT_FALSE(parseRequest("{\"cmd\":", err));
  EXPECT_EQ(err.rfind("not JSON", 0), 0u);
  // Found by fuzz_request (issue 37): a number beyond double (json out_of_range 406, not a
  // parse_error) escaped parseRequest, and in fusedetd the server thread: std::terminate, the
  // daemon gone for any local client that sent it. Now it is an error line like any bad JSON.
  EXPECT_FALSE(parseRequest(R"({"cid":{"a":[1e20305,.,null]]}})", err));
  EXPECT_FALSE(parseRequest(R"({"cmd":"status","x":1e999})", err));
  EXPECT_EQ(err.rfind("not JSON", 0), 0u) << err;
  EXPECT_NE(err.find("number overflow"), std::string::npos) << err;
}

TEST(Protocol, GarbageNeverThrowsAndAlwaysSaysWhy) {
  std::mt19937 rng(13);
  const std::string seed = R"({"cmd":"subscribe","classes":["car"],"id":"x"})";
  for (int i = 0; i < 20000; ++i) {
    std::string s = seed;
    const int edits = 1 + static_cast<int>(rng() % 6);
    for (int e = 0; e < edits; ++e) {
      const std::size_t at = rng() % (s.size() + 1);
      switch (rng() % 3) {
        case 0: if (at < s.size()) s.erase(at, 1); break;
        case 1: s.insert(s.begin() + static_cast<std::ptrdiff_t>(at), static_cast<char>(rng() % 256)); break;
        default: if (at < s.size()) s[at] = static_cast<char>(rng() % 256);
      }
    }
    std::string err;
    std::optional<Request> r;
    ASSERT_NO_THROW(r = parseRequest(s, err)) << s;
    if (!r) {
      EXPECT_FALSE(err.empty()) << s;
    }
  }
}

TEST(Protocol, ResultLineFiltersClassesAndCarriesStampsAndPositions) {
  StackResult r;
  r.stackId = 4;
  r.sweepStart = Stamp{100};
  r.sweepEnd = Stamp{200};
  r.frameStamp = Stamp{150};
  r.sensorStamp = Stamp{200};
  LocatedDetection car, bike;
  car.detection.className = "car";
  car.detection.box = {1, 2, 3, 4};
  Position p;
  p.camera = {1, 2, 3};
  p.robot = {3, -1, -2};
  p.range = 3.74;
  car.position = p;
  bike.detection.className = "bike";
  r.detections = {car, bike};
  const auto all = resultToJson(r);
  EXPECT_EQ(all["detections"].size(), 2u);
  EXPECT_EQ(all["frame_ns"], 150);
  EXPECT_EQ(all["sweep_start_ns"], 100);
  const auto onlyBike = resultToJson(r, {"bike"});
  ASSERT_EQ(onlyBike["detections"].size(), 1u);
  EXPECT_TRUE(onlyBike["detections"][0]["camera"].is_null());
  const auto c = all["detections"][0];
  EXPECT_EQ(c["box"], nlohmann::json({1, 2, 3, 4}));
  EXPECT_EQ(c["robot"], nlohmann::json({3, -1, -2}));
  EXPECT_EQ(errorLine("x", 5), "{\"error\":\"x\",\"id\":5,\"type\":\"error\"}\n");
}

TEST(Protocol, TrackFieldsAndTheTracksStream) {
  std::string err;
  auto r = parseRequest(R"({"cmd":"subscribe","stream":"tracks","classes":["car"]})", err);
  ASSERT_TRUE(r) << err;
  EXPECT_EQ(r->stream, "tracks");
  EXPECT_EQ(parseRequest(R"({"cmd":"subscribe"})", err)->stream, "detections");
  EXPECT_EQ(parseRequest(R"({"cmd":"unsubscribe"})", err)->stream, "");
  EXPECT_EQ(parseRequest(R"({"cmd":"unsubscribe","stream":"tracks"})", err)->stream, "tracks");
  EXPECT_FALSE(parseRequest(R"({"cmd":"subscribe","stream":"everything"})", err));
  EXPECT_NE(err.find("stream"), std::string::npos) << err;
  EXPECT_FALSE(parseRequest(R"({"cmd":"status","stream":"tracks"})", err));

  StackResult s;
  s.stackId = 9;
  s.frameStamp = Stamp{500};
  LocatedDetection tracked, untracked;
  tracked.detection.className = "car";
  tracked.track = 0;
  untracked.detection.className = "person";
  s.detections = {tracked, untracked};
  tracking::TrackState car, person;
  car.id = 7;
  car.className = "car";
  car.confirmed = true;
  car.velocity = {1.5, -0.5, 0};
  car.ageS = 2.5;
  person.id = 8;
  person.className = "person";
  person.coasting = true;
  s.tracks = {car, person};
  const auto line = resultToJson(s);
  EXPECT_EQ(line["detections"][0]["track"], 7);
  EXPECT_EQ(line["detections"][0]["velocity"], nlohmann::json({1.5, -0.5, 0}));
  EXPECT_EQ(line["detections"][0]["age"], 2.5);
  EXPECT_EQ(line["detections"][0]["confirmed"], true);
  EXPECT_TRUE(line["detections"][1]["track"].is_null());
  EXPECT_EQ(line["detections"][1]["confirmed"], false);
  const auto tracks = tracksToJson(s);
  EXPECT_EQ(tracks["type"], "tracks");
  EXPECT_EQ(tracks["stack"], 9);
  ASSERT_EQ(tracks["tracks"].size(), 2u);
  EXPECT_EQ(tracks["tracks"][1]["id"], 8);
  EXPECT_EQ(tracks["tracks"][1]["coasting"], true);
  EXPECT_EQ(tracks["tracks"][1]["confirmed"], false);
  EXPECT_EQ(tracksToJson(s, {"car"})["tracks"].size(), 1u);
}

TEST(DetectionSettings, ConfigDefaultsAreTheLibraryDefaults) {
  const Config::Detection d;
  const boosting::ScanParams s = scanParamsFrom(d), lib;
  EXPECT_EQ(s.step, lib.step);
  EXPECT_EQ(s.scaleFactor, lib.scaleFactor);
  EXPECT_EQ(s.minWidth, lib.minWidth);
  EXPECT_EQ(s.maxWidth, lib.maxWidth);
  const boosting::GroupParams g = groupParamsFrom(d), glib;
  EXPECT_EQ(g.minNeighbors, glib.minNeighbors);
  EXPECT_EQ(g.eps, glib.eps);
  EXPECT_EQ(laserExtentFrom(d).enabled, boosting::LaserExtentParams{}.enabled);
  // Per class: the built-in list is the library's (car), and the scan fusedet experiments measures
  // car with is the daemon's, so its docs/results figures are what fusedetd does for car.
  const std::vector<boosting::ClassGrouping> perClass = classGroupingFrom(d);
  ASSERT_EQ(perClass.size(), boosting::classesWithOwnDetection().size());
  ASSERT_EQ(perClass.size(), 1u);
  for (const boosting::ClassGrouping& k : perClass) {
    const std::optional<boosting::ClassDetection> own = boosting::classDetectionDefault(k.className);
    ASSERT_TRUE(own.has_value()) << k.className;
    EXPECT_EQ(k.minNeighbors, own->minNeighbors);
    EXPECT_EQ(k.laserExtent, own->laserExtent);
    EXPECT_EQ(own->scaleFactor, s.scaleFactor);
    EXPECT_EQ(own->step, s.step);
  }
  for (const char* other : {"person", "bike"}) EXPECT_FALSE(boosting::classDetectionDefault(other).has_value());
}

// detection.classes entries are matched to the loaded models by class name: the built-in car entry
// matches the bundled car model; a misspelt or undeployed class is reported, not silently dropped.
TEST(DetectionSettings, ClassSettingsWithoutAModelAreReported) {
  Config::Detection d;
  d.models = {std::string(FUSEDET_SOURCE_DIR) + "/models/car.json", std::string(FUSEDET_SOURCE_DIR) + "/models/bike.json"};
  EXPECT_TRUE(CascadeSet(d).unmatchedClassSettings().empty());
  d.classes = {{"car", 16, true}, {"cars", 4, false}, {"person", 5, false}};
  EXPECT_EQ(CascadeSet(d).unmatchedClassSettings(), (std::vector<std::string>{"cars", "person"}));
}

// A model trained on a layer the daemon's stacks do not have (here the bundled car model with a
// neural score layer added to its layer list) is refused when loaded, naming the file,
// the layer and the layers fusion makes; hue_distance counts as made (derived from hue). With the
// layer made by a network, the model must record that very network (kind, input, digests).
TEST(DetectionSettings, AModelNeedingALayerTheStacksLackIsRefused) {
  nlohmann::json car = nlohmann::json::parse(std::ifstream(std::string(FUSEDET_SOURCE_DIR) + "/models/car.json"));
  car["layers"].push_back("neural_car");
  const std::string file = testing::TempDir() + "/car_neural.json";
  std::ofstream(file) << car.dump();
  Config::Detection d;
  d.models = {file};
  try {
    CascadeSet set(d);
    FAIL() << "loaded a model needing neural_car";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(file + ": the model (class 'car') uses layer 'neural_car', which fusedetd's stacks do not have "
                               "(red, green, blue, intensity, hue, distance, remission, hue_distance)"),
              std::string::npos)
        << what;
  }
  // Stacks that have the layer: the model must record the network that makes it, the same one.
  std::vector<std::string> layers = fusion::Fuser::layerNames();
  layers.push_back("neural_car");
  const NetworkRecord running{"darknet", 832, 256, {"a.cfg", "a.weights"}, {std::string(64, 'a'), std::string(64, 'b')}};
  const auto refusal = [&] {
    try {
      CascadeSet set(d, {}, layers, running);
    } catch (const std::runtime_error& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(refusal().find(file + " (class 'car'): uses neural layers but records no network"), std::string::npos)
      << refusal();
  NetworkRecord other = running;
  other.inputWidth = 1248;
  car["network"] = other.text();
  std::ofstream(file, std::ios::trunc) << car.dump();
  const std::string what = refusal();
  EXPECT_NE(what.find(file + " (class 'car'): trained on neural layers of the network " + other.text()), std::string::npos)
      << what;
  EXPECT_NE(what.find("fusedetd's network (config section neural) has the network " + running.text()), std::string::npos)
      << what;
  car["network"] = running.text();
  std::ofstream(file, std::ios::trunc) << car.dump();
  EXPECT_EQ(CascadeSet(d, {}, layers, running).classes(), std::vector<std::string>{"car"});
  // Without hue, a model using hue_distance cannot run either.
  d.models = {std::string(FUSEDET_SOURCE_DIR) + "/models/car.json"};
  EXPECT_THROW(CascadeSet(d, {}, {"red", "green", "blue", "intensity", "distance", "remission"}), std::runtime_error);
}

// neural.enabled with a network file that is not there: fusedetd refuses to start, naming the
// section and the file; off (the default), no network is loaded at all.
TEST(DetectionSettings, AMissingNetworkIsNamedAtStart) {
  Config c;
  EXPECT_EQ(neuralLayersFrom(c, "/etc/fusedet/fusedet.yaml"), nullptr);
  c.neural.enabled = true;
  c.neural.directory = "nets";  // relative: to the config's folder
  try {
    (void)neuralLayersFrom(c, testing::TempDir() + "/fusedet.yaml");
    FAIL() << "loaded a network that is not there";
  } catch (const std::runtime_error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("neural (network darknet 832x256): "), std::string::npos) << what;
    EXPECT_NE(what.find("nets/yolo-fastest-1.1-xl.cfg: network file (darknet) not found"), std::string::npos) << what;
  }
}

// detection.classes: each entry inherits the general min_neighbors / laser_extent it leaves out;
// given, the list replaces the built-in one ({} = none); unknown keys are named.
TEST(DetectionSettings, PerClassKeys) {
  const Config c = parseConfig(
      "detection:\n  min_neighbors: 2\n  laser_extent: true\n  classes:\n    person: {min_neighbors: 7}\n"
      "    car: {laser_extent: false}\n",
      "test.yaml");
  const std::vector<boosting::ClassGrouping> k = classGroupingFrom(c.detection);
  ASSERT_EQ(k.size(), 2u);
  EXPECT_EQ(k[0].className, "person");
  EXPECT_EQ(k[0].minNeighbors, 7);
  EXPECT_TRUE(k[0].laserExtent);
  EXPECT_EQ(k[1].className, "car");
  EXPECT_EQ(k[1].minNeighbors, 2);
  EXPECT_FALSE(k[1].laserExtent);
  const Config back = parseConfig(dumpConfig(c), "dump.yaml");
  EXPECT_EQ(dumpConfig(back), dumpConfig(c));
  ASSERT_EQ(back.detection.classes.size(), 2u);
  EXPECT_EQ(back.detection.classes[0].minNeighbors, 7);
  EXPECT_TRUE(parseConfig("detection:\n  classes: {}\n", "t.yaml").detection.classes.empty());
  EXPECT_EQ(parseConfig("detection:\n  min_neighbors: 5\n", "t.yaml").detection.classes.size(), 1u);
  try {
    (void)parseConfig("detection:\n  classes:\n    car: {neighbours: 3}\n", "t.yaml");
    ADD_FAILURE() << "an unknown per-class key was accepted";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("unknown key detection.classes.car.neighbours"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)parseConfig("detection:\n  classes: [car]\n", "t.yaml"), ConfigError);
  EXPECT_THROW((void)parseConfig("detection:\n  classes:\n    car: {min_neighbors: -1}\n", "t.yaml"), ConfigError);
}

// Non-default values written in fusedet.yaml reach the library unchanged, in its units: step in
// base-window pixels (not a fraction of the window), sizes in reference pixels.
TEST(DetectionSettings, YamlKeysMeanWhatTheLibraryMeans) {
  const Config c = parseConfig(
      "detection:\n  step: 3\n  scale_factor: 1.25\n  min_size: [30, 60]\n  max_size: [300, 400]\n"
      "  min_neighbors: 5\n  laser_extent: true\n  threads: 1\n",
      "test.yaml");
  const boosting::ScanParams s = scanParamsFrom(c.detection);
  EXPECT_EQ(s.step, 3.0);
  EXPECT_EQ(s.scaleFactor, 1.25);
  EXPECT_EQ(s.minWidth, 30);
  EXPECT_EQ(s.minHeight, 60);
  EXPECT_EQ(s.maxWidth, 300);
  EXPECT_EQ(s.maxHeight, 400);
  EXPECT_EQ(s.threads, 1);
  const boosting::GroupParams g = groupParamsFrom(c.detection);
  EXPECT_EQ(g.minNeighbors, 5);
  EXPECT_TRUE(laserExtentFrom(c.detection).enabled);
  // NMS grouping was removed (it lost on every measure): its keys are refused by name, saying so.
  for (const char* removed : {"grouping: nms", "grouping: opencv", "nms_iou: 0.5"}) {
    try {
      parseConfig(std::string("detection:\n  ") + removed + "\n", "t.yaml");
      ADD_FAILURE() << removed << " accepted";
    } catch (const ConfigError& e) {
      const std::string key = std::string(removed).substr(0, std::string(removed).find(':'));
      EXPECT_NE(std::string(e.what()).find("t.yaml:2: key detection." + key + " was removed"), std::string::npos) << e.what();
    }
  }
}

// A 200 x 100 image, laser layers at half size: background at 20 m, an object at 5 m covering
// the box, a few filled cells at 1 m that must not count.
TEST(Localize, NearSurfaceInsideTheBoxOnTheCentreRay) {
  LayerStack stack(200, 100);
  cv::Mat dist(50, 100, CV_32F, cv::Scalar(20.0f)), mask(50, 100, CV_8U, cv::Scalar(fusion::kMaskMeasured));
  dist(cv::Rect(40, 10, 20, 30)).setTo(5.0f);
  dist(cv::Rect(48, 24, 3, 3)).setTo(1.0f);
  mask(cv::Rect(48, 24, 3, 3)).setTo(fusion::kMaskFilled);
  stack.set(Layer{"distance", dist, mask});
  Eigen::Matrix3d K;
  K << 100, 0, 100, 0, 100, 50, 0, 0, 1;
  // Box (reference px) = laser cells [35, 65) x [5, 45) doubled: the object plus background.
  const Box box{70, 10, 60, 80};
  Eigen::Isometry3d sweepToCamera = Eigen::Isometry3d::Identity();
  sweepToCamera.translation() = Eigen::Vector3d(0, 0, -1);
  const auto p = localize(stack, box, K, sweepToCamera);
  ASSERT_TRUE(p);
  EXPECT_FLOAT_EQ(static_cast<float>(p->range), 5.0f);
  // Centre pixel (100, 50) is the principal point: straight ahead.
  EXPECT_NEAR(p->camera.x(), 0, 1e-9);
  EXPECT_NEAR(p->camera.z(), 5, 1e-9);
  EXPECT_NEAR(p->robot.z(), 6, 1e-9);  // robot = camera - translation
  // No measured cells: no position.
  LayerStack empty(200, 100);
  empty.set(Layer{"distance", cv::Mat(50, 100, CV_32F, cv::Scalar(0.0f)), cv::Mat(50, 100, CV_8U, cv::Scalar(0))});
  EXPECT_FALSE(localize(empty, box, K, sweepToCamera));
  EXPECT_FALSE(localize(LayerStack(200, 100), box, K, sweepToCamera));
}
