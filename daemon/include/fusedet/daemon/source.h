#pragma once
// Source: one sensor input of the pipeline on its own thread - a live device driver (LMS 291
// today; tilt motor and camera when their drivers land) or a replay of recorded data. A source
// hands every message to its SensorSink, which never blocks (bounded, drop-oldest queue), and
// reports its health for the `status` request.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fusedet/drivers/messages.h"
#include "fusedet/fusion/sweep.h"

namespace fusedet::daemon {

// A sweep already assembled and paired with its camera frame (sources whose data comes in that
// shape, e.g. recorded scenes); skips sweep assembly and pairing, not fusion.
struct PairedScene {
  fusion::Sweep sweep;
  drivers::CameraFrame frame;
};

class SensorSink {
 public:
  virtual ~SensorSink() = default;
  // All of these return at once (the message is queued or, if the queue is full, the oldest one
  // is dropped and counted).
  virtual void onScan(drivers::LaserScan scan) = 0;
  virtual void onTilt(drivers::TiltSample sample) = 0;
  virtual void onFrame(drivers::CameraFrame frame) = 0;
  virtual void onScene(PairedScene scene) = 0;
};

// What `status` reports per sensor.
struct SensorHealth {
  std::string name;    // "laser", "tilt", "camera", "replay", ...
  std::string state;   // "streaming", "connecting", "backing-off", "stopped", "finished", ...
  std::uint64_t messages = 0;    // messages delivered to the pipeline
  std::uint64_t crcErrors = 0;
  std::uint64_t reconnects = 0;
  std::uint64_t lost = 0;        // messages the device or source knows it lost
  std::string lastError;
};

class Source {
 public:
  virtual ~Source() = default;
  // Starts the source's own thread; messages go to `sink` until stop(). Must not block long.
  virtual void start(SensorSink& sink) = 0;
  // Stops and joins the thread; no sink call happens after it returns.
  virtual void stop() = 0;
  virtual std::vector<SensorHealth> health() const = 0;
};

}  // namespace fusedet::daemon
