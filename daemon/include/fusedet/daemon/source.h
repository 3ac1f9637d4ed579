// SPDX-License-Identifier: Apache-2.0
#pragma once
// Source: one sensor input of the pipeline on its own thread - a live device driver (LMS 291,
// tilt motor, camera) or a replay of recorded data (a sensor log, recorded scenes). A source
// hands every message to its SensorSink, which never blocks (bounded, drop-oldest queue), and
// reports its health for the `status` request.

#include <atomic>
#include <chrono>
#include <cstdint>
#include <memory>
#include <optional>
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
  // End of a finite stream (a replayed log, or one pass of a looping one): the open sweep is
  // closed and fused with its frame, and the sweep and pairing state start afresh.
  virtual void onEndOfStream() = 0;
  // Only for a source that loses nothing by waiting (a log replayed as fast as possible): returns
  // once the next message can be taken without dropping anything, or when `stop` is set.
  virtual void awaitRoom(const std::atomic<bool>& stop) = 0;
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
  std::optional<double> progress;  // replay: fraction of the log's messages replayed (this pass)
  std::uint64_t passes = 0;        // replay: complete passes through the log
};

class Source {
 public:
  virtual ~Source() = default;
  // Starts the source's own thread; messages go to `sink` until stop(). Must not block long.
  virtual void start(SensorSink& sink) = 0;
  // Stops and joins the thread; no sink call happens after it returns.
  virtual void stop() = 0;
  virtual std::vector<SensorHealth> health() const = 0;
  // A finite source (a replayed log, recorded scenes) that has delivered everything it will.
  virtual bool finished() const { return false; }
  // Finished because of an error it could not recover from (health().lastError says which).
  virtual bool failed() const { return false; }
  // The longest stop() can take (a tilt motor is brought to rest first): the daemon's stop
  // budget covers the sum over its sources.
  virtual std::chrono::milliseconds stopTime() const { return std::chrono::milliseconds(0); }
  // After stop(): "" when the source stopped safely, else what is not safe (a motor that did not
  // confirm it is at rest). fusedetd then exits 1.
  virtual std::string stopProblem() const { return {}; }
};

}  // namespace fusedet::daemon
