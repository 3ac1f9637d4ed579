// SPDX-License-Identifier: Apache-2.0
// Velocity through the daemon's pipeline where the truth is known: a flat object (a 1 m x 1 m
// board facing the robot) moves at a constant robot-frame velocity; each stack is its sweep
// (points written here) paired with a camera frame at irregular stamps, one stack missing. The
// pipeline fuses, a detector that boxes the measured cells of the distance layer finds it, the
// pipeline localises it from the distance layer and tracks it: the track's velocity must be the
// board's, in the robot frame (x ahead, y left, z up; the camera looks along x).

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <thread>

#include "fusedet/daemon/pipeline.h"
#include "pipeline_fixtures.h"

using namespace fusedet;
using namespace fusedet::daemon;

namespace {

// Boxes the measured cells of the distance layer: the board is the only thing the laser sees.
class BoardDetector : public StackDetector {
 public:
  std::vector<Detection> detect(const LayerStack& stack) const override {
    const Layer& d = stack.at(layer::kDistance);
    cv::Mat measured = d.hasMask() ? d.valid : (d.data > 0);
    const cv::Rect r = cv::boundingRect(measured);
    if (r.area() == 0) return {};
    const double sx = static_cast<double>(stack.width()) / d.width(), sy = static_cast<double>(stack.height()) / d.height();
    Detection det;
    det.className = "car";
    det.score = 1;
    det.box = Box{r.x * sx, r.y * sy, r.width * sx, r.height * sy};
    det.unitBox = stack.toUnit(det.box);
    return {det};
  }
  std::vector<std::string> classes() const override { return {"car"}; }
};

// Robot frame (x ahead, y left, z up) -> camera frame (x right, y down, z ahead).
Eigen::Isometry3d robotToCamera() {
  Eigen::Matrix3d R;
  R << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = R;
  return T;
}

const Eigen::Vector3d kStart{20.0, -1.0, 0.2};     // board centre at t = 0 [m]
const Eigen::Vector3d kVelocity{-1.2, 0.3, 0.0};    // [m/s]: approaching, drifting left (in view throughout)

PairedScene sceneAt(double t, int width, int height) {
  const Eigen::Vector3d c = kStart + t * kVelocity;
  PairedScene s;
  const std::int64_t ns = 10'000'000'000 + static_cast<std::int64_t>(std::llround(t * 1e9));
  s.sweep.start = Stamp{ns - 700'000'000};
  s.sweep.end = Stamp{ns + 700'000'000};
  for (double dy = -0.5; dy <= 0.5; dy += 0.01)
    for (double dz = -0.5; dz <= 0.5; dz += 0.01)
      s.sweep.points.push_back({static_cast<float>(c.x()), static_cast<float>(c.y() + dy), static_cast<float>(c.z() + dz), 0.5f, ns});
  s.frame.stamp = Stamp{ns};
  s.frame.format = drivers::PixelFormat::kBgr24;
  s.frame.width = width;
  s.frame.height = height;
  s.frame.stride = 3 * width;
  s.frame.bytes.assign(static_cast<std::size_t>(s.frame.stride * height), 90);
  return s;
}

}  // namespace

TEST(PipelineVelocity, ATrackOfABoardMovingAtConstantVelocityHasThatVelocity) {
  const fusion::CameraModel camera = fixtures::pinholeCamera(320, 240, 300);
  PipelineSetup setup;
  setup.fuser = std::make_shared<const fusion::Fuser>(camera, robotToCamera());
  setup.lossless = true;
  fixtures::Results results;
  Pipeline pipeline(setup, std::make_shared<BoardDetector>(), results.handler());
  pipeline.start();
  // Irregular stack stamps [s]; the stack at 4.0 s is missing (dropped).
  const double stamps[] = {0.0, 1.0, 2.3, 3.0, 5.1, 6.0, 7.4, 8.0, 9.2, 10.0};
  for (double t : stamps) {
    pipeline.onScene(sceneAt(t, camera.width, camera.height));
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!pipeline.idle() && std::chrono::steady_clock::now() < deadline) std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  pipeline.stop(std::chrono::steady_clock::now() + std::chrono::seconds(5));
  const std::vector<StackResult> got = results.all();
  ASSERT_EQ(got.size(), std::size(stamps));
  for (std::size_t k = 0; k < got.size(); ++k) {
    const StackResult& r = got[k];
    ASSERT_EQ(r.detections.size(), 1u) << "stack " << k;
    ASSERT_TRUE(r.detections[0].position) << "stack " << k;
    ASSERT_EQ(r.tracks.size(), 1u) << "one board, one track, stack " << k;
    EXPECT_EQ(r.tracks[0].id, 1u) << "stack " << k;
    // The localised position is the board's centre (the nearest part of the board along the box
    // centre's ray; the board is 1 m wide, so within 0.15 m).
    const Eigen::Vector3d truth = kStart + 1e-9 * static_cast<double>(r.frameStamp.ns - 10'000'000'000) * kVelocity;
    EXPECT_LT((r.detections[0].position->robot - truth).norm(), 0.15) << "stack " << k;
  }
  // After the first stacks the filter has the velocity: within 0.1 m/s from the 5th stack on,
  // 0.05 m/s at the end; the detections carry their track's velocity.
  for (std::size_t k = 4; k < got.size(); ++k) {
    const tracking::TrackState& t = got[k].tracks[0];
    EXPECT_TRUE(t.confirmed);
    EXPECT_LT((t.velocity - kVelocity).norm(), 0.1) << "stack " << k << ": " << t.velocity.transpose();
  }
  const tracking::TrackState& last = got.back().tracks[0];
  for (std::size_t k = 1; k < got.size(); ++k)
    std::printf("stack %zu t %.1f s: velocity %.3f %.3f %.3f m/s, error %.3f m/s\n", k,
                1e-9 * static_cast<double>(got[k].frameStamp.ns - 10'000'000'000), got[k].tracks[0].velocity.x(),
                got[k].tracks[0].velocity.y(), got[k].tracks[0].velocity.z(), (got[k].tracks[0].velocity - kVelocity).norm());
  EXPECT_LT((last.velocity - kVelocity).norm(), 0.05) << last.velocity.transpose();
  EXPECT_NEAR(last.ageS, 10.0, 1e-9);
}
