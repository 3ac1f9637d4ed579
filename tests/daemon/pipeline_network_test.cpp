// SPDX-License-Identifier: Apache-2.0
// The network's own stage in fusedetd's pipeline (config section neural; issue 30), on a replayed
// sensor log with Yolo-Fastest-XL from ../shared/models and the bundled models plus one that reads
// the network's neural_car layer:
//  - on its own thread the network gives the layers and detections of running it inline (the
//    layers made again from the stack's camera image by the same NeuralLayers, the detector run
//    on that stack), every stack once, in order, its time in stages_ms and status;
//  - a run that fails (cv::dnn throws; an output of another shape) drops no stack: the models that
//    do not need the network's layers detect what they detect with a working network, the one that
//    needs them gives nothing, the line names the error and the class not run, status counts the
//    failures and sd_notify's status line says the network is failing.

#include <gtest/gtest.h>
#include <unistd.h>

#include <atomic>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <set>
#include <thread>

#include "fusedet/daemon/client.h"
#include "fusedet/daemon/pipeline.h"
#include "fusedet/daemon/protocol.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/daemon/server.h"
#include "fusedet/daemon/service.h"
#include "fusedet/daemon/service_parts.h"
#include "fusedet/fusion/camera_layers.h"
#include "replay_logs.h"

using namespace fusedet;
using namespace fusedet::daemon;
using namespace std::chrono_literals;
namespace fs = std::filesystem;

namespace {

constexpr int kStrokes = 3;  // stacks of the test log

std::string model(const std::string& cls) { return std::string(FUSEDET_SOURCE_DIR) + "/models/" + cls + ".json"; }

fusion::NeuralLayerOptions networkOptions() {
  fusion::NeuralLayerOptions o;
  o.kind = fusion::NetworkKind::darknet;
  o.directory = FUSEDET_NETWORKS_DIR;
  return o;
}

// The bundled car model with one more stump on the network's neural_car layer (centre vs
// surround), recording `network`: a class ("car_net") whose decisions depend on the network.
std::string carNetModel(const NetworkRecord& network) {
  nlohmann::json car = nlohmann::json::parse(std::ifstream(model("car")));
  car["class"] = "car_net";
  car["layers"].push_back("neural_car");
  car["network"] = network.text();
  car["stages"][0]["stumps"].push_back(
      {{"type", "f"}, {"rect", {0.0, 0.0, 1.0, 1.0}}, {"layer", "neural_car"}, {"threshold", 0.0}, {"left", -0.4}, {"right", 0.6}});
  const std::string file = testing::TempDir() + "/car_net-" + std::to_string(::getpid()) + ".json";
  std::ofstream(file) << car.dump();
  return file;
}

Config neuralConfig(const fs::path& log, const NetworkRecord& network) {
  Config c;
  c.detection.models = {model("car"), model("bike"), model("person"), carNetModel(network)};
  c.replay.file = log.string();
  c.replay.realtime = false;
  c.replay.restamp = false;
  c.replay.atEnd = "idle";
  c.neural.enabled = true;
  c.neural.directory = FUSEDET_NETWORKS_DIR;
  return c;
}

// The replay's parts with this network (a test's NeuralLayers, or the config's when null).
ServiceParts partsWith(const Config& config, std::shared_ptr<const fusion::NeuralLayers> neural = {}) {
  ServiceParts parts = replayParts(config, {}, false);
  if (neural) {
    const ReplayRig rig = replayRig(config.replay.file, config, {});
    parts.fuser = fuserFrom(rig.config, rig.camera, std::move(neural));
  }
  parts.detector = detectorFrom(config, {}, *parts.fuser);
  return parts;
}

struct Replayed {
  std::vector<std::shared_ptr<const StackResult>> results;
  PipelineCounters counters;
  std::set<std::string> threads;  // this process's thread names while the results came
};

std::set<std::string> threadNames() {
  std::set<std::string> names;
  for (const auto& task : fs::directory_iterator("/proc/self/task")) {
    std::string name;
    std::getline(std::ifstream(task.path() / "comm"), name);
    names.insert(name);
  }
  return names;
}

// The log through the pipeline, lossless, every result kept with its layers.
Replayed replay(ServiceParts parts) {
  PipelineSetup setup = pipelineSetup(parts);
  setup.keepViews = true;
  Replayed run;
  std::mutex mutex;
  Pipeline pipeline(std::move(setup), parts.detector, [&](std::shared_ptr<const StackResult> r) {
    std::lock_guard lock(mutex);
    run.results.push_back(std::move(r));
    for (std::string name : threadNames()) run.threads.insert(std::move(name));
  });
  pipeline.start();
  for (auto& s : parts.sources) s->start(pipeline);
  const auto end = std::chrono::steady_clock::now() + 300s;
  const auto done = [&] {
    for (const auto& s : parts.sources)
      if (!s->finished()) return false;
    return pipeline.idle();
  };
  while (!done() && std::chrono::steady_clock::now() < end) std::this_thread::sleep_for(10ms);
  for (auto& s : parts.sources) s->stop();
  pipeline.stop(std::chrono::steady_clock::now() + 10s);
  run.counters = pipeline.counters();
  return run;
}

std::vector<Detection> detectionsOf(const StackResult& r) {
  std::vector<Detection> out;
  for (const LocatedDetection& d : r.detections) out.push_back(d.detection);
  return out;
}

void expectSameDetections(const std::vector<Detection>& a, const std::vector<Detection>& b, const std::string& what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].className, b[i].className) << what << " #" << i;
    EXPECT_EQ(a[i].score, b[i].score) << what << " #" << i;
    EXPECT_EQ(a[i].box.x, b[i].box.x) << what << " #" << i;
    EXPECT_EQ(a[i].box.y, b[i].box.y) << what << " #" << i;
    EXPECT_EQ(a[i].box.w, b[i].box.w) << what << " #" << i;
    EXPECT_EQ(a[i].box.h, b[i].box.h) << what << " #" << i;
  }
}

std::vector<Detection> withoutClass(const std::vector<Detection>& in, const std::string& cls) {
  std::vector<Detection> out;
  for (const Detection& d : in)
    if (d.className != cls) out.push_back(d);
  return out;
}

std::size_t countClass(const std::vector<Detection>& in, const std::string& cls) {
  std::size_t n = 0;
  for (const Detection& d : in) n += d.className == cls;
  return n;
}

}  // namespace

TEST(NetworkStage, OnItsOwnThreadItGivesTheInlineLayersAndDetections) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  const auto network = std::make_shared<const fusion::NeuralLayers>(networkOptions());
  const Config config = neuralConfig(log, network->record());
  ServiceParts parts = partsWith(config);
  ASSERT_TRUE(parts.fuser->neural());
  const auto detector = parts.detector;
  const Replayed run = replay(std::move(parts));

  ASSERT_EQ(run.results.size(), static_cast<std::size_t>(kStrokes));
  EXPECT_TRUE(run.counters.network);
  EXPECT_EQ(run.counters.networkRuns, static_cast<std::uint64_t>(kStrokes));
  EXPECT_EQ(run.counters.networkErrors, 0u);
  EXPECT_EQ(run.counters.networkQueue.pushed, static_cast<std::uint64_t>(kStrokes));
  EXPECT_EQ(run.counters.networkQueue.dropped, 0u);
  EXPECT_EQ(run.counters.networkMs.samples, static_cast<std::size_t>(kStrokes));
  EXPECT_GT(run.counters.networkMs.p50Ms, 0.0);
  EXPECT_EQ(run.counters.fuseErrors, 0u);
  EXPECT_TRUE(run.threads.count("fd-network")) << "the network runs on a thread of its own";
  std::size_t netDetections = 0;
  for (std::size_t k = 0; k < run.results.size(); ++k) {
    const StackResult& r = *run.results[k];
    EXPECT_EQ(r.stackId, k) << "every stack once, in order";
    EXPECT_EQ(r.networkError, "");
    EXPECT_TRUE(r.classesNotRun.empty());
    EXPECT_GT(r.stages.neuralMs, 0.0);
    EXPECT_GE(r.stages.neuralQueueMs, 0.0);
    ASSERT_TRUE(r.view);
    const LayerStack& threaded = r.view->layers;
    EXPECT_EQ(threaded.network, network->record());

    // Inline: the stack's neural layers zeroed, made again from its camera image (the
    // undistorted image the network thread had) by the same network, then detected.
    LayerStack inlineStack = threaded;
    for (const std::string& name : network->layerNames()) {
      const Layer& l = threaded.at(name);
      inlineStack.set(Layer{name, cv::Mat::zeros(l.data.size(), l.data.type()), {}});
    }
    inlineStack.network = {};
    network->add(inlineStack, fusion::cameraImage(threaded));
    for (const std::string& name : network->layerNames()) {
      const cv::Mat& a = threaded.at(name).data;
      const cv::Mat& b = inlineStack.at(name).data;
      ASSERT_EQ(a.size(), b.size()) << name;
      EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0.0) << "stack " << k << " layer " << name;
    }
    EXPECT_GT(cv::countNonZero(threaded.at("neural_car").data), 0) << "the network sees cars in the KITTI frames";
    const std::vector<Detection> inlineFound = detector->detect(inlineStack);
    expectSameDetections(detectionsOf(r), inlineFound, "stack " + std::to_string(k));
    netDetections += countClass(inlineFound, "car_net");
  }
  EXPECT_GT(netDetections, 0u) << "the class that reads neural_car finds cars";
}

TEST(NetworkStage, AFailingRunServesNoDetectionsOfTheModelsThatNeedItsLayers) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  // The network works on the first stack; cv::dnn throws on the second; the third's output has
  // one anchor row too few.
  std::atomic<int> calls{0};
  const auto failing = std::make_shared<const fusion::NeuralLayers>(
      networkOptions(), [&calls](fusion::Network& n, const cv::Mat& bgr) {
        const int call = calls++;
        if (call == 1) CV_Error(cv::Error::StsAssert, "injected: a layer's blob has the wrong shape");
        fusion::Anchors a = n.run(bgr);
        if (call == 2) {
          a.boxes.pop_back();
          a.objectness.pop_back();
          a.scores = a.scores.rowRange(0, a.scores.rows - 1).clone();
        }
        return a;
      });
  const auto working = std::make_shared<const fusion::NeuralLayers>(networkOptions());
  const Config config = neuralConfig(log, working->record());
  const Replayed good = replay(partsWith(config, working));
  ASSERT_EQ(good.results.size(), static_cast<std::size_t>(kStrokes));

  // Through the service: the socket's lines, status and the sd_notify status line.
  const std::string socket = (fs::temp_directory_path() / ("fusedet-net-" + std::to_string(::getpid()) + ".sock")).string();
  ServiceParts parts = partsWith(config, failing);
  parts.listener = bindUnixSocket(socket);
  Service service(std::move(parts));
  Client client(socket);
  client.send({{"cmd", "subscribe"}});
  service.start();
  std::vector<nlohmann::json> lines;
  const auto end = std::chrono::steady_clock::now() + 300s;
  while (std::chrono::steady_clock::now() < end) {
    auto m = client.read(200ms);
    if (m && (*m)["type"] == "detections") lines.push_back(*m);
    if (!m && service.finished()) break;
  }
  while (auto m = client.read(500ms))
    if ((*m)["type"] == "detections") lines.push_back(*m);
  const nlohmann::json status = service.status();
  const std::string summary = service.summary();
  service.stop(std::chrono::steady_clock::now() + 2s);

  // No stack dropped: each is served, the failed ones without the network's class.
  ASSERT_EQ(lines.size(), static_cast<std::size_t>(kStrokes)) << status.dump();
  EXPECT_FALSE(lines[0].contains("network_error"));
  for (int k : {1, 2}) {
    const nlohmann::json& line = lines[k];
    ASSERT_TRUE(line.contains("network_error")) << line.dump();
    EXPECT_EQ(line["classes_not_run"], nlohmann::json::array({"car_net"}));
    const std::vector<Detection> expected = withoutClass(detectionsOf(*good.results[k]), "car_net");
    ASSERT_EQ(line["detections"].size(), expected.size()) << line.dump();
    for (std::size_t i = 0; i < expected.size(); ++i) {
      EXPECT_EQ(line["detections"][i]["class"], expected[i].className);
      EXPECT_EQ(line["detections"][i]["score"], expected[i].score);
      EXPECT_EQ(line["detections"][i]["box"][0], expected[i].box.x);
      EXPECT_EQ(line["detections"][i]["box"][1], expected[i].box.y);
    }
  }
  const std::string identity = working->record().text();
  const std::string thrown = lines[1]["network_error"];
  EXPECT_NE(thrown.find("network " + identity + " on a "), std::string::npos) << thrown;
  EXPECT_NE(thrown.find("cv::dnn failed: injected: a layer's blob has the wrong shape"), std::string::npos) << thrown;
  const std::string shape = lines[2]["network_error"];
  constexpr std::size_t rows = 3 * (26 * 8 + 52 * 16);  // Yolo-Fastest-XL's two YOLO layers at 832x256
  EXPECT_NE(shape.find("output of " + std::to_string(rows - 1) + " anchor rows x 80 classes where it gave " +
                       std::to_string(rows) + " x 80 at load"),
            std::string::npos)
      << shape;
  // The stack the network worked on is served whole, the network's class included.
  const std::vector<Detection> first = detectionsOf(*good.results[0]);
  ASSERT_EQ(lines[0]["detections"].size(), first.size());
  for (std::size_t i = 0; i < first.size(); ++i) {
    EXPECT_EQ(lines[0]["detections"][i]["class"], first[i].className);
    EXPECT_EQ(lines[0]["detections"][i]["score"], first[i].score);
  }

  const nlohmann::json& net = status["pipeline"]["network"];
  ASSERT_TRUE(net.is_object()) << status.dump();
  EXPECT_EQ(net["runs"], kStrokes);
  EXPECT_EQ(net["errors"], 2);
  EXPECT_EQ(net["failing"], true);
  EXPECT_EQ(net["last_error"], shape);
  EXPECT_EQ(net["network"], identity);
  EXPECT_EQ(status["pipeline"]["fuse_errors"], 0);
  EXPECT_EQ(status["pipeline"]["stacks_detected"], kStrokes);
  EXPECT_NE(summary.find("network failing (2 failed runs): " + shape), std::string::npos) << summary;
}

// Without a network there is no network stage: no thread, no queue traffic, status says null.
TEST(NetworkStage, WithoutANetworkThereIsNone) {
  const fs::path log = testlogs::daemonTestLog(kStrokes);
  Config config;
  config.detection.models = {model("car")};
  config.replay.file = log.string();
  config.replay.realtime = false;
  config.replay.restamp = false;
  const Replayed run = replay(partsWith(config));
  ASSERT_EQ(run.results.size(), static_cast<std::size_t>(kStrokes));
  EXPECT_FALSE(run.counters.network);
  EXPECT_TRUE(run.threads.count("fd-fusion"));
  EXPECT_FALSE(run.threads.count("fd-network"));
  EXPECT_EQ(run.counters.networkQueue.pushed, 0u);
  EXPECT_EQ(run.counters.networkRuns, 0u);
  for (const auto& r : run.results) {
    EXPECT_EQ(r->stages.neuralMs, 0.0);
    EXPECT_FALSE(r->view->layers.has("neural_car"));
  }
}
