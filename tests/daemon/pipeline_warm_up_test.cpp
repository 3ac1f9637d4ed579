// SPDX-License-Identifier: Apache-2.0
// Before its first stack the pipeline readies the detector on a blank stack of the rig's sizes,
// from the detection thread (StackDetector::prepare), and delivers nothing of it: the first real
// stack is stack 0 and the only one counted.

#include <gtest/gtest.h>
#include <pthread.h>

#include <chrono>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "fusedet/daemon/pipeline.h"
#include "pipeline_fixtures.h"

using namespace fusedet;
using namespace fusedet::daemon;

namespace {

std::string threadName() {
  char name[16] = {};
  pthread_getname_np(pthread_self(), name, sizeof name);
  return name;
}

// Records what prepare() and detect() saw, in call order.
class RecordingDetector : public StackDetector {
 public:
  struct Call {
    std::string what, thread;
    int width = 0, height = 0;
    std::vector<std::string> layers;
  };
  mutable std::mutex m;
  mutable std::vector<Call> calls;

  std::vector<Detection> detect(const LayerStack& stack) const override {
    note("detect", stack);
    return {};
  }
  std::vector<std::string> classes() const override { return {"none"}; }
  void prepare(const LayerStack& stack) const override { note("prepare", stack); }

 private:
  void note(const char* what, const LayerStack& stack) const {
    Call c{what, threadName(), stack.width(), stack.height(), {}};
    for (const Layer& l : stack.layers()) c.layers.push_back(l.name);
    std::lock_guard lock(m);
    calls.push_back(std::move(c));
  }
};

}  // namespace

TEST(PipelineWarmUp, TheDetectorIsPreparedOnABlankStackOfTheRigBeforeTheFirstStackAndNothingOfItIsDelivered) {
  const fusion::CameraModel camera = fixtures::pinholeCamera(80, 60, 60);
  PipelineSetup setup;
  setup.fuser = std::make_shared<const fusion::Fuser>(camera, Eigen::Isometry3d::Identity());
  auto detector = std::make_shared<RecordingDetector>();
  fixtures::Results results;
  Pipeline pipeline(setup, detector, results.handler());
  pipeline.start();

  // One scene: a few points 5 m ahead and a grey frame.
  PairedScene scene;
  scene.sweep.start = Stamp{1'000'000'000};
  scene.sweep.end = Stamp{1'100'000'000};
  for (int i = 0; i < 50; ++i) scene.sweep.points.push_back(fusion::SweepPoint{-0.5f + 0.02f * i, 0.f, 5.f, 0.5f, 0});
  scene.frame.stamp = Stamp{1'050'000'000};
  scene.frame.width = camera.width;
  scene.frame.height = camera.height;
  scene.frame.stride = 3 * camera.width;
  scene.frame.bytes.assign(static_cast<std::size_t>(scene.frame.stride * scene.frame.height), 100);
  pipeline.onScene(scene);
  ASSERT_TRUE(results.waitFor(1, std::chrono::seconds(20)));
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  while (!pipeline.idle() && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  const PipelineCounters counters = pipeline.counters();
  pipeline.stop(std::chrono::steady_clock::now() + std::chrono::seconds(2));

  std::lock_guard lock(detector->m);
  const auto& calls = detector->calls;
  ASSERT_EQ(calls.size(), 2u) << "one prepare, one detect";
  const auto& prep = calls[0];
  EXPECT_EQ(prep.what, "prepare") << "prepared before the first stack's detection";
  EXPECT_EQ(prep.thread, "fd-detect");
  EXPECT_EQ(prep.width, camera.width);
  EXPECT_EQ(prep.height, camera.height);
  EXPECT_EQ(prep.layers, calls[1].layers) << "the blank stack has the real stacks' layers";
  EXPECT_EQ(calls[1].what, "detect");
  EXPECT_EQ(calls[1].width, camera.width);
  // Nothing of the warm-up is delivered or counted: the scene is stack 0, and the only one.
  const std::vector<StackResult> delivered = results.all();
  ASSERT_EQ(delivered.size(), 1u);
  EXPECT_EQ(delivered[0].stackId, 0u);
  EXPECT_EQ(counters.stacksFused, 1u);
  EXPECT_EQ(counters.stacksDetected, 1u);
}
