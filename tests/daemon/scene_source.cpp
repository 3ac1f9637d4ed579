// SPDX-License-Identifier: Apache-2.0
#include "scene_source.h"

#include "fusedet/core/stamp.h"
#include "fusedet/daemon/thread_info.h"

namespace fusedet::daemon {

SceneSource::SceneSource(std::vector<PairedScene> scenes, std::chrono::milliseconds period, std::size_t rounds)
    : scenes_(std::move(scenes)), period_(period), rounds_(rounds) {}

SceneSource::~SceneSource() { stop(); }

void SceneSource::start(SensorSink& sink) {
  thread_ = std::thread([this, &sink] { run(sink); });
}

void SceneSource::stop() {
  {
    std::lock_guard lock(mutex_);
    stopping_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

void SceneSource::run(SensorSink& sink) {
  nameThisThread("fd-scenes");
  auto next = std::chrono::steady_clock::now();
  for (std::size_t round = 0; rounds_ == 0 || round < rounds_; ++round) {
    for (const PairedScene& original : scenes_) {
      {
        std::unique_lock lock(mutex_);
        if (wake_.wait_until(lock, next, [this] { return stopping_; })) return;
      }
      next += period_;
      PairedScene scene = original;
      // Re-stamp as if measured now: the sweep ends now, the frame is taken now.
      const Stamp now = Stamp::now();
      const std::int64_t shift = now - scene.sweep.end;
      scene.sweep.start = scene.sweep.start + shift;
      scene.sweep.end = now;
      for (auto& p : scene.sweep.points)
        if (p.stampNs) p.stampNs += shift;
      scene.frame.stamp = now;
      scene.frame.sequence = emitted_.load();
      scene.sweep.id = emitted_.load();
      sink.onScene(std::move(scene));
      ++emitted_;
    }
  }
  finished_ = true;
}

std::vector<SensorHealth> SceneSource::health() const {
  SensorHealth h;
  h.name = "scenes";
  h.state = finished_ ? "finished" : "streaming";
  h.messages = emitted_.load();
  return {h};
}

}  // namespace fusedet::daemon
