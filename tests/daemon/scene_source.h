// SPDX-License-Identifier: Apache-2.0
#pragma once
// SceneSource: plays a list of recorded scenes (sweep + camera frame pairs) into the pipeline at
// a fixed period, as a sensor would: each scene is stamped with the time it is emitted (the
// sweep keeps its duration and ends then), so latencies measured downstream are real. Used for
// in-process runs of the whole daemon (tests, latency benchmark) on recorded data.

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "fusedet/daemon/source.h"

namespace fusedet::daemon {

class SceneSource : public Source {
 public:
  // rounds: how many times the list is played (0 = until stopped).
  SceneSource(std::vector<PairedScene> scenes, std::chrono::milliseconds period, std::size_t rounds = 1);
  ~SceneSource() override;
  void start(SensorSink& sink) override;
  void stop() override;
  std::vector<SensorHealth> health() const override;
  // Scenes emitted so far.
  std::uint64_t emitted() const { return emitted_.load(); }
  bool finished() const override { return finished_.load(); }

 private:
  void run(SensorSink& sink);

  std::vector<PairedScene> scenes_;
  std::chrono::milliseconds period_;
  std::size_t rounds_;
  std::thread thread_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool stopping_ = false;
  std::atomic<std::uint64_t> emitted_{0};
  std::atomic<bool> finished_{false};
};

}  // namespace fusedet::daemon
