// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the pipeline tests share: a distortion-free camera for the rig, and the results a pipeline
// hands over, collected.

#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <memory>
#include <mutex>
#include <vector>

#include "fusedet/daemon/pipeline.h"

namespace fusedet::daemon::fixtures {

// A pinhole camera of width x height pixels without distortion: focal length `focal` pixels, the
// principal point at the image's centre.
inline fusion::CameraModel pinholeCamera(int width, int height, double focal) {
  fusion::CameraModel c;
  c.width = width;
  c.height = height;
  c.K << focal, 0, width / 2.0, 0, focal, height / 2.0, 0, 0, 1;
  return c;
}

// Every result a pipeline hands over (handler()), copied in order.
struct Results {
  std::mutex m;
  std::condition_variable cv;
  std::vector<StackResult> got;

  Pipeline::ResultHandler handler() {
    return [this](std::shared_ptr<const StackResult> r) {
      std::lock_guard lock(m);
      got.push_back(*r);
      cv.notify_all();
    };
  }
  // True once at least n results came, false after `timeout` without them.
  bool waitFor(std::size_t n, std::chrono::milliseconds timeout) {
    std::unique_lock lock(m);
    return cv.wait_for(lock, timeout, [&] { return got.size() >= n; });
  }
  std::vector<StackResult> all() {
    std::lock_guard lock(m);
    return got;
  }
};

}  // namespace fusedet::daemon::fixtures
