// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a sensor log as fusedetd's replay uses it (daemon/src/rig.cpp, replay_source):
// the rig it carries (metadata fusedet.config: config.yaml through parseConfig, camera.yaml
// through parseCameraModel), then every raw message through SensorReplay - serial bytes into the
// LMS telegram reader and scan decoder, CAN frames into the TPDO1 decoder - and every camera
// frame through decodeCameraFrame. The input is an anonymous memory file opened by path.
// Allowed: McapError (not MCAP, I/O), ConfigError and the camera model's runtime_error for a bad
// rig (the daemon refuses such a log and says why), a refused frame (Result error). A decoded
// frame must have the size the message says; anything else thrown is a finding.

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <stdexcept>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/frame_decode.h"
#include "memory_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace fusedet;
  const fuzz::MemoryFile file(data, size);
  if (!file.ok()) return 0;
  // The rig, as fusedetd reads it before replaying (a relative calibration path of the default
  // config resolves in a folder that does not exist: only the log's own camera.yaml can load).
  daemon::Config config;
  try {
    config = daemon::replayRig(file.path(), daemon::Config{}, "/nonexistent").config;
  } catch (const std::runtime_error&) {  // McapError, ConfigError, camera model: the log is refused
    config = daemon::Config{};           // the raw streams still go through the decoders below
  }
  try {
    drivers::logs::SensorReplay replay(file.path(), daemon::sensorReplayConfig(config));
    drivers::logs::SensorReplay::Handlers handlers;
    handlers.frame = [](const drivers::CameraFrame& frame) {
      const auto image = fusion::decodeCameraFrame(frame);
      if (image && (image->cols != frame.width || image->rows != frame.height)) std::abort();
    };
    replay.run(handlers);
  } catch (const drivers::mcap::McapError&) {
  }
  return 0;
}
