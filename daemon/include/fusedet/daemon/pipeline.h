// SPDX-License-Identifier: Apache-2.0
#pragma once
// Pipeline: sensor messages -> sweep assembly -> pairing -> fusion (fusion thread) -> every class
// (detection thread) -> 3D positions -> tracks (tracking::Tracker, detection thread) -> StackResult handed to a callback (the socket server). Sources run on their
// own threads and push into the sensor queue through the SensorSink interface; the queues are
// bounded (the sensor queue by count and bytes) and drop their oldest item when full (counted), so no producer ever waits. When
// detection falls behind, the stack queue (2 deep) drops the oldest stack. Lossless mode (a log
// replayed as fast as possible) is the exception: there the source waits for room (awaitRoom)
// and fusion for detection, so every stack is detected and a replay is deterministic.
//
// With a network (the fuser's NeuralLayers, config section neural) one more stage and thread
// sits between fusion and detection: the fusion thread makes every other layer
// (Fuser::fuseSensors) and hands the stack with its undistorted image to the network thread
// (`fd-network`, Fuser::addNetworkLayers), which hands it on to detection. So the network's run on
// one stack overlaps the fusion of the next sweep and the detection of the previous stack. The
// network queue is 1 deep and drops its oldest stack (counted) like the stack queue: live, a
// fresher stack is worth more than an older one, and waiting instead would stall fusion until
// the sensor queue drops raw scans and frames, which breaks sweeps instead of skipping a whole
// one; in lossless mode fusion waits for the network thread instead. The stacks pass the network
// one at a time, in order, through the same calls fuse() makes, so the layers and detections are
// those of running the network inline. Without a network there is no such thread or queue.
//
// A network run that fails (cv::dnn throws, an output of another shape: NeuralLayers::add) does
// not drop the stack: it goes on without the network's layers, the classes whose models need them
// are not run on it and the result names them and the error (StackResult::networkError,
// classesNotRun); `status` counts the failures and shows the last error, and the journal says
// when the network starts failing and when it works again.

#include <atomic>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <variant>
#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"
#include "fusedet/daemon/bounded_queue.h"
#include "fusedet/daemon/localize.h"
#include "fusedet/daemon/source.h"
#include "fusedet/daemon/stack_detector.h"
#include "fusedet/daemon/stats.h"
#include "fusedet/daemon/thread_info.h"
#include "fusedet/fusion/fuser.h"
#include "fusedet/fusion/pairing.h"
#include "fusedet/fusion/sweep_assembler.h"
#include "fusedet/tracking/tracker.h"

namespace fusedet::daemon {

struct LocatedDetection {
  Detection detection;               // detection.position = the robot-frame position, if any
  std::optional<Position> position;  // camera and robot frame, range, cells used
  int track = -1;                    // index into StackResult::tracks; -1 = not tracked (no position)
};

// Where one stack's time went, in milliseconds: wall time, and the thread's own CPU time where
// it says Cpu (on a loaded machine wall time also counts waiting for a core).
struct StageTimes {
  double closeMs = 0;      // sensor stamp -> fusion starts on the pair: sweep closing (by the tilt
                           // sample that proves the turn, else the next stroke's first scan),
                           // pairing, the sensor queue
  double decodeMs = 0;     // camera frame -> BGR image
  double fuseMs = 0;       // Fuser::fuse: undistortion, camera layers, projection, laser layers
  double fuseCpuMs = 0;    // the fusion thread's CPU time for decode + fuse
  // The network (config section neural; all 0 when off), on the network thread:
  double neuralQueueMs = 0;  // in the network queue, waiting for the network thread
  double neuralMs = 0;       // the network's run and its score layers (Fuser::addNetworkLayers)
  double neuralCpuMs = 0;    // the network thread's CPU time for it (OpenCV's helper threads not counted)
  double queueMs = 0;      // in the stack queue, waiting for the detection thread
  double detectMs = 0;     // every class: integrals, window scan, grouping
  double detectCpuMs = 0;  // the detection thread's CPU time for it (helper threads not counted)
  double localizeMs = 0;   // 3D positions of the detections
  double trackMs = 0;      // the tracker's update (tracking::Tracker)
};

// What a viewer draws of one stack (the live view, daemon/live/): the fused layers (the
// undistorted camera image as red, green, blue; the laser layers) and the sweep's points in its
// own frame (laser_base). Kept only with PipelineSetup::keepViews.
struct StackView {
  LayerStack layers;
  std::vector<fusion::SweepPoint> sweep;
};

// Everything the detection thread found in one stack.
struct StackResult {
  std::uint64_t stackId = 0;
  Stamp sweepStart, sweepEnd;  // the sweep's first and last beam
  Stamp frameStamp;            // the camera frame
  Stamp sensorStamp;           // the newest sensor stamp that went into the stack
  Stamp detectedAt;            // when detection finished
  double fuseMs = 0, detectMs = 0;  // detectMs: detection + localisation
  StageTimes stages;
  std::vector<LocatedDetection> detections;
  // The network failed on this stack (its error; empty when it ran or there is none): the
  // classes whose models need its layers were not run (classesNotRun) and have no detections.
  std::string networkError;
  std::vector<std::string> classesNotRun;
  // Every live track after this stack (tentative, confirmed, coasting), ascending id.
  std::vector<tracking::TrackState> tracks;
  std::shared_ptr<const StackView> view;  // with PipelineSetup::keepViews, else empty
};

struct PipelineSetup {
  std::shared_ptr<const fusion::Fuser> fuser;  // camera model, extrinsics, laser layer settings
  fusion::SweepConfig sweep;
  std::int64_t maxPairSkewNs = 150'000'000;
  std::size_t sensorQueueCapacity = 512;  // messages between sources and fusion
  std::size_t sensorQueueBytes = 64u << 20;  // and their bytes: ~16 1080p YUYV frames (512 would be 2 GB)
  std::size_t pairerBytes = 64u << 20;      // camera frames waiting for their sweep (fusion::FramePairer)
  std::size_t stackQueueCapacity = 2;     // fused stacks waiting for detection
  std::size_t networkQueueCapacity = 1;   // fused stacks waiting for the network (with one)
  // Fusion waits for room in the stack queue instead of dropping the oldest stack. Only for
  // sources that can wait too (a log replayed as fast as possible), never for live devices.
  bool lossless = false;
  tracking::TrackerParams tracking;  // the tracker after detection (config `tracking`)
  // Each result carries its layers and sweep (StackResult::view) for the live view: the layers
  // are handed over after detection (no copy), the sweep's points are copied once.
  bool keepViews = false;
  // The detection thread and the scan's helpers each on a CPU of their own (thread_placement.h):
  // pipelineSetup() sets it when detection.threads is 0 (the helpers work in the detection
  // thread's arena); decided at start.
  bool pinDetection = false;
};

struct PipelineCounters {
  QueueCounters sensorQueue, stackQueue;  // stackQueue.dropped = stacks detection never saw
  // The network stage (zero when the fuser has no network): networkQueue.dropped = stacks the
  // network never saw; the network's per-stack wall time (its run and score layers) over the
  // last 1024 stacks; failed runs, the last one's error, and whether the last run failed.
  bool network = false;
  QueueCounters networkQueue;
  std::uint64_t networkRuns = 0, networkErrors = 0;
  LatencySummary networkMs;
  double lastNetworkMs = 0;
  bool networkFailing = false;
  std::string lastNetworkError;
  fusion::SweepStats sweeps;
  std::uint64_t scenes = 0;         // pre-paired scenes received
  std::uint64_t handled = 0;        // sensor-queue messages the fusion thread finished with
  std::uint64_t streamEnds = 0;     // end-of-stream marks handled (replay passes)
  std::uint64_t unpaired = 0;       // sweeps without a frame within the skew
  std::uint64_t decodeErrors = 0;   // camera frames that did not decode
  std::uint64_t fuseErrors = 0;
  std::uint64_t stacksFused = 0;
  std::uint64_t stacksDetected = 0;
  std::uint64_t detectErrors = 0;
  std::uint64_t detections = 0;
  double scanRate = 0, tiltRate = 0, frameRate = 0, stackRate = 0;  // per second, last 5 s
  double lastFuseMs = 0, lastDetectMs = 0;
};

class Pipeline : public SensorSink {
 public:
  using ResultHandler = std::function<void(std::shared_ptr<const StackResult>)>;

  // onResult is called on the detection thread; it must not block (the server only queues).
  Pipeline(PipelineSetup setup, std::shared_ptr<const StackDetector> detector, ResultHandler onResult);
  ~Pipeline() override;
  Pipeline(const Pipeline&) = delete;
  Pipeline& operator=(const Pipeline&) = delete;

  // Starts the threads. With a network, first sets OpenCV's process-wide thread count to the
  // network's (neural.threads) once, so that no run changes it while fusion uses OpenCV
  // (network.h, Determinism).
  void start();
  // Refuses new messages, lets fusion and detection finish what is queued until `deadline`
  // (steady clock), then abandons the rest and joins the threads.
  void stop(std::chrono::steady_clock::time_point deadline);

  // Swaps the detector between two stacks (SIGHUP reload).
  void setDetector(std::shared_ptr<const StackDetector> detector);
  std::shared_ptr<const StackDetector> detector() const;
  // The fuser (fixed for the pipeline's life): the layers and network its stacks have.
  const fusion::Fuser& fuser() const { return *setup_.fuser; }

  // SensorSink: never block.
  void onScan(drivers::LaserScan scan) override;
  void onTilt(drivers::TiltSample sample) override;
  void onFrame(drivers::CameraFrame frame) override;
  void onScene(PairedScene scene) override;
  void onEndOfStream() override;
  // Waits for room for at least half the sensor queue (or `stop`, or the pipeline stopping).
  void awaitRoom(const std::atomic<bool>& stop) override;

  // Nothing queued or in work: every message taken is handled and every fused stack detected
  // (or dropped), its result handed to the result callback.
  bool idle() const;

  PipelineCounters counters() const;
  // Steady-clock ns of the last sign of life of the fusion and detection threads (each wakes at
  // least every 200 ms while idle). A thread stuck in one stack stops advancing its beat.
  std::int64_t fusionBeatNs() const { return fusionBeat_.load(); }
  std::int64_t detectionBeatNs() const { return detectionBeat_.load(); }
  // The network thread's (with a network; else 0: there is none).
  std::int64_t networkBeatNs() const { return networkBeat_.load(); }
  bool hasNetworkThread() const { return hasNetwork_; }

 private:
  struct EndOfStream {};
  using SensorMessage =
      std::variant<drivers::LaserScan, drivers::TiltSample, drivers::CameraFrame, PairedScene, EndOfStream>;
  static std::size_t bytesOf(const SensorMessage& message);
  struct FusedStack {
    LayerStack stack;
    std::vector<fusion::SweepPoint> sweep;  // with setup_.keepViews
    Stamp sweepStart, sweepEnd, frameStamp;
    double fuseMs = 0;
    StageTimes stages;
    std::chrono::steady_clock::time_point queuedAt;
    cv::Mat image;             // the undistorted camera image, until the network ran on it
    std::string networkError;  // the network's run failed
  };

  void fusionLoop();
  void networkLoop();
  void detectionLoop();
  // Each thread's stage readied on a blank stack before its first real one (pipeline.cpp says why):
  // fusion fuses it and hands it over in blankStack_ (null when that failed), detection prepares on it.
  void warmUpFusion();
  void warmUpDetection();
  std::promise<std::shared_ptr<const LayerStack>> blankStack_;
  // Pushes `fused` into `queue`; in lossless mode waits for room first, showing liveness in
  // `beat`. False when the pipeline stops meanwhile (the stack is dropped).
  bool handOver(BoundedQueue<FusedStack>& queue, FusedStack&& fused, std::atomic<std::int64_t>& beat);
  // The network on one stack: its layers, or the failure noted on the stack and counted.
  void runNetwork(FusedStack& fused);
  void handle(SensorMessage& message);
  void fuseAndQueue(const fusion::Sweep& sweep, const drivers::CameraFrame& frame);
  // Runs the tracker on one stack's located detections: sets each detection's track and the
  // stack's live tracks (stamp: the camera frame's).
  void track(StackResult& result);

  PipelineSetup setup_;
  ResultHandler onResult_;
  mutable std::mutex detectorMutex_;
  std::shared_ptr<const StackDetector> detector_;

  BoundedQueue<SensorMessage> sensorQueue_;
  BoundedQueue<FusedStack> stackQueue_;
  const bool hasNetwork_;              // the fuser has a network: the network stage runs
  BoundedQueue<FusedStack> networkQueue_;
  fusion::SweepAssembler assembler_;   // fusion thread only
  fusion::FramePairer pairer_;         // fusion thread only
  std::uint64_t nextStackId_ = 0;      // fusion thread only
  tracking::Tracker tracker_;          // detection thread only

  std::thread fusionThread_, networkThread_, detectionThread_;
  std::atomic<bool> abandon_{false}, detectionDone_{false};
  std::atomic<std::int64_t> fusionBeat_{0}, networkBeat_{0}, detectionBeat_{0};
  LatencyRecorder networkTimes_;

  mutable std::mutex countersMutex_;
  PipelineCounters counters_;
  RateMeter scanRate_, tiltRate_, frameRate_, stackRate_;
};

}  // namespace fusedet::daemon
