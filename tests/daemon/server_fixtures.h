// SPDX-License-Identifier: Apache-2.0
#pragma once
// What the socket server tests feed the server: a socket path in a folder of this test process,
// and synthetic stack results (no detection cost, so the tests are about the server).

#include <memory>
#include <string>

#include "../process_temp_dir.h"
#include "fusedet/daemon/pipeline.h"

namespace fusedet::daemon::server_test {

inline std::string tempSocket(const std::string& name) {
  return (test::processTempDir() / name).string();
}

// Stack `id` stamped now with `detections` boxes, cars and bikes in turn (10: ~1.5 kB per line).
inline std::shared_ptr<const StackResult> makeResult(std::uint64_t id, int detections = 10) {
  auto r = std::make_shared<StackResult>();
  r->stackId = id;
  r->sensorStamp = Stamp::now();
  r->frameStamp = r->sensorStamp;
  for (int i = 0; i < detections; ++i) {
    LocatedDetection d;
    d.detection.className = i % 2 ? "car" : "bike";
    d.detection.score = i;
    d.detection.box = {double(i), 2, 30, 40};
    r->detections.push_back(d);
  }
  return r;
}

}  // namespace fusedet::daemon::server_test
