// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/pipeline.h"

#include <spdlog/spdlog.h>

#include <chrono>
#include <optional>
#include <string>
#include <opencv2/core/utility.hpp>

#include "fusedet/core/cpu_time.h"
#include "fusedet/daemon/thread_placement.h"
#include "fusedet/fusion/frame_decode.h"

namespace fusedet::daemon {
namespace {
constexpr std::chrono::milliseconds kIdleWake{200};  // threads show liveness at least this often
}  // namespace

// The first stack through a thread used to pay for what later ones reuse: fresh buffers (page
// faults, zeroed pages). Measured in bench_daemon_latency (bench/README.md): the first stack's
// integral tables 17 ms against 3 ms, its detection 78-85 ms against 39-61 ms, its fusion 12-17 ms
// against 7-9 ms - the p99 of a short run was that one stack. So the fusion thread fuses a blank
// stack (a black image, an empty sweep) of the rig's sizes before its first real one and hands it
// to the detection thread, which readies the detector on it (StackDetector::prepare: the tables,
// no model runs). Only the fusion thread fuses: two threads fusing at once raced inside OpenCV
// (ThreadSanitizer). Nothing of it is counted, queued or delivered; a failure only costs the warm-up.
void Pipeline::warmUpFusion() {
  std::shared_ptr<const LayerStack> blank;
  try {
    const auto& p = setup_.fuser->projection();
    cv::Mat undistorted;
    blank = std::make_shared<const LayerStack>(
        setup_.fuser->fuseSensors(cv::Mat::zeros(p.height, p.width, CV_8UC3), fusion::Sweep{}, &undistorted));
  } catch (const std::exception& e) {
    spdlog::warn("fusion warm-up on a blank stack: {} (the first stacks run cold)", e.what());
  }
  blankStack_.set_value(std::move(blank));
}

void Pipeline::warmUpDetection() {
  const std::shared_ptr<const LayerStack> blank = blankStack_.get_future().get();
  if (!blank) return;  // the fusion warm-up failed and said so
  try {
    detector()->prepare(*blank);
  } catch (const std::exception& e) {
    spdlog::warn("detection warm-up on a blank stack: {} (its first stack runs cold)", e.what());
  }
}

Pipeline::Pipeline(PipelineSetup setup, std::shared_ptr<const StackDetector> detector, ResultHandler onResult)
    : setup_(std::move(setup)),
      onResult_(std::move(onResult)),
      detector_(std::move(detector)),
      sensorQueue_(setup_.sensorQueueCapacity, setup_.sensorQueueBytes, &Pipeline::bytesOf),
      stackQueue_(setup_.stackQueueCapacity),
      hasNetwork_(setup_.fuser && setup_.fuser->neural()),
      networkQueue_(std::max<std::size_t>(1, setup_.networkQueueCapacity)),
      assembler_(setup_.sweep),
      pairer_(setup_.maxPairSkewNs, 32, setup_.pairerBytes),
      tracker_(setup_.tracking) {
  if (!setup_.fuser) throw std::invalid_argument("Pipeline: no fuser");
  if (!detector_) throw std::invalid_argument("Pipeline: no detector");
}

Pipeline::~Pipeline() { stop(std::chrono::steady_clock::now()); }

std::size_t Pipeline::bytesOf(const SensorMessage& message) {
  struct Size {
    std::size_t operator()(const drivers::LaserScan& s) const {
      return sizeof s + (s.ranges.size() + s.remissions.size()) * sizeof(float);
    }
    std::size_t operator()(const drivers::TiltSample& t) const { return sizeof t; }
    std::size_t operator()(const drivers::CameraFrame& f) const { return sizeof f + f.bytes.size(); }
    std::size_t operator()(const PairedScene& p) const {
      return sizeof p + p.sweep.points.size() * sizeof(fusion::SweepPoint) + p.frame.bytes.size();
    }
    std::size_t operator()(const EndOfStream&) const { return 0; }
  };
  return std::visit(Size{}, message);
}

void Pipeline::start() {
  const std::int64_t now = Stamp::now().ns;
  fusionBeat_ = now;
  detectionBeat_ = now;
  if (hasNetwork_) {
    networkBeat_ = now;
    cv::setNumThreads(setup_.fuser->neural()->threads());
    networkThread_ = std::thread([this] { networkLoop(); });
  }
  fusionThread_ = std::thread([this] { fusionLoop(); });
  detectionThread_ = std::thread([this] { detectionLoop(); });
}

void Pipeline::stop(std::chrono::steady_clock::time_point deadline) {
  // Fusion drains the closed sensor queue and then closes the next queue (the network's, else
  // the stack queue); the network thread drains its queue and closes the stack queue; detection
  // ends when that is empty. Whatever is still queued at the deadline is abandoned.
  sensorQueue_.close();
  while (detectionThread_.joinable() && !detectionDone_ && std::chrono::steady_clock::now() < deadline)
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  abandon_ = true;
  networkQueue_.close();
  stackQueue_.close();
  if (fusionThread_.joinable()) fusionThread_.join();
  if (networkThread_.joinable()) networkThread_.join();
  if (detectionThread_.joinable()) detectionThread_.join();
}

void Pipeline::setDetector(std::shared_ptr<const StackDetector> detector) {
  std::lock_guard lock(detectorMutex_);
  detector_ = std::move(detector);
}

std::shared_ptr<const StackDetector> Pipeline::detector() const {
  std::lock_guard lock(detectorMutex_);
  return detector_;
}

void Pipeline::onScan(drivers::LaserScan scan) {
  scanRate_.tick(Stamp::now().ns);
  sensorQueue_.push(std::move(scan));
}
void Pipeline::onTilt(drivers::TiltSample sample) {
  tiltRate_.tick(Stamp::now().ns);
  sensorQueue_.push(sample);
}
void Pipeline::onFrame(drivers::CameraFrame frame) {
  frameRate_.tick(Stamp::now().ns);
  sensorQueue_.push(std::move(frame));
}
void Pipeline::onScene(PairedScene scene) {
  const std::int64_t now = Stamp::now().ns;
  scanRate_.tick(now);
  frameRate_.tick(now);
  sensorQueue_.push(std::move(scene));
}

void Pipeline::onEndOfStream() { sensorQueue_.push(EndOfStream{}); }

void Pipeline::awaitRoom(const std::atomic<bool>& stop) {
  const std::size_t maxDepth = sensorQueue_.capacity() / 2;
  while (!stop && !sensorQueue_.waitForRoom(maxDepth, kIdleWake))
    if (sensorQueue_.closed()) return;
}

bool Pipeline::idle() const {
  const PipelineCounters c = counters();
  return c.sensorQueue.depth == 0 && c.handled == c.sensorQueue.pushed - c.sensorQueue.dropped &&
         c.networkQueue.depth == 0 && c.stackQueue.depth == 0 &&
         c.stacksFused == c.stacksDetected + c.detectErrors + c.stackQueue.dropped + c.networkQueue.dropped;
}

void Pipeline::fusionLoop() {
  nameThisThread("fd-fusion");
  warmUpFusion();
  while (!abandon_) {
    fusionBeat_ = Stamp::now().ns;
    auto message = sensorQueue_.pop(kIdleWake);
    if (!message) {
      if (sensorQueue_.closed()) break;
      continue;
    }
    try {
      handle(*message);
    } catch (const std::exception& e) {
      std::lock_guard lock(countersMutex_);
      ++counters_.fuseErrors;
      spdlog::warn("fusion: {}", e.what());
    }
    std::lock_guard lock(countersMutex_);
    ++counters_.handled;
  }
  (hasNetwork_ ? networkQueue_ : stackQueue_).close();
}

void Pipeline::handle(SensorMessage& message) {
  if (auto* scan = std::get_if<drivers::LaserScan>(&message)) {
    assembler_.addScan(*scan);
  } else if (auto* tilt = std::get_if<drivers::TiltSample>(&message)) {
    assembler_.addTilt(*tilt);
  } else if (auto* frame = std::get_if<drivers::CameraFrame>(&message)) {
    pairer_.addFrame(std::move(*frame));
  } else if (auto* scene = std::get_if<PairedScene>(&message)) {
    {
      std::lock_guard lock(countersMutex_);
      ++counters_.scenes;
    }
    fuseAndQueue(scene->sweep, scene->frame);
  } else if (std::holds_alternative<EndOfStream>(message)) {
    assembler_.flush();  // the last sweep has no reversal to close it
    std::lock_guard lock(countersMutex_);
    ++counters_.streamEnds;
  }
  for (const fusion::Sweep& sweep : assembler_.takeSweeps())
    if (auto frame = pairer_.pair(sweep)) fuseAndQueue(sweep, *frame);
  std::lock_guard lock(countersMutex_);
  counters_.sweeps = assembler_.stats();
  counters_.unpaired = pairer_.unpaired();
}

void Pipeline::fuseAndQueue(const fusion::Sweep& sweep, const drivers::CameraFrame& frame) {
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = threadCpuMs();
  FusedStack fused;
  fused.stages.closeMs = static_cast<double>(Stamp::now().ns - std::max(sweep.end, frame.stamp).ns) * 1e-6;
  Result<cv::Mat> bgr = fusion::decodeCameraFrame(frame);
  if (!bgr) {
    std::lock_guard lock(countersMutex_);
    ++counters_.decodeErrors;
    spdlog::warn("camera frame {}: {}", frame.sequence, bgr.error().message());
    return;
  }
  const auto t1 = std::chrono::steady_clock::now();
  // With a network its layers come on the network thread (networkLoop), from the undistorted image.
  fused.stack = hasNetwork_ ? setup_.fuser->fuseSensors(bgr.value(), sweep, &fused.image) : setup_.fuser->fuse(bgr.value(), sweep);
  fused.stack.id = nextStackId_++;
  fused.stack.stamp = frame.stamp;
  fused.stack.source = "pipeline";
  fused.sweepStart = sweep.start;
  fused.sweepEnd = sweep.end;
  if (setup_.keepViews) fused.sweep = sweep.points;
  fused.frameStamp = frame.stamp;
  const auto t2 = std::chrono::steady_clock::now();
  fused.fuseMs = std::chrono::duration<double, std::milli>(t2 - t0).count();
  fused.stages.decodeMs = std::chrono::duration<double, std::milli>(t1 - t0).count();
  fused.stages.fuseMs = std::chrono::duration<double, std::milli>(t2 - t1).count();
  fused.stages.fuseCpuMs = threadCpuMs() - cpu0;
  {
    std::lock_guard lock(countersMutex_);
    ++counters_.stacksFused;
    counters_.lastFuseMs = fused.fuseMs;
  }
  handOver(hasNetwork_ ? networkQueue_ : stackQueue_, std::move(fused), fusionBeat_);
}

bool Pipeline::handOver(BoundedQueue<FusedStack>& queue, FusedStack&& fused, std::atomic<std::int64_t>& beat) {
  if (setup_.lossless)
    while (!queue.waitForRoom(queue.capacity() - 1, kIdleWake)) {
      if (abandon_ || queue.closed()) return false;
      beat = Stamp::now().ns;  // waiting for the next stage is not a stall of this thread
    }
  fused.queuedAt = std::chrono::steady_clock::now();
  queue.push(std::move(fused));
  return true;
}

void Pipeline::networkLoop() {
  nameThisThread("fd-network");
  while (!abandon_) {
    networkBeat_ = Stamp::now().ns;
    auto fused = networkQueue_.pop(kIdleWake);
    if (!fused) {
      if (networkQueue_.closed()) break;
      continue;
    }
    runNetwork(*fused);
    handOver(stackQueue_, std::move(*fused), networkBeat_);
  }
  stackQueue_.close();
}

void Pipeline::runNetwork(FusedStack& fused) {
  const auto t0 = std::chrono::steady_clock::now();
  const double cpu0 = threadCpuMs();
  fused.stages.neuralQueueMs = std::chrono::duration<double, std::milli>(t0 - fused.queuedAt).count();
  try {
    setup_.fuser->addNetworkLayers(fused.stack, fused.image);
  } catch (const std::exception& e) {
    fused.networkError = e.what();
  }
  fused.image.release();
  fused.stages.neuralMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  fused.stages.neuralCpuMs = threadCpuMs() - cpu0;
  networkTimes_.add(fused.stages.neuralMs);
  std::lock_guard lock(countersMutex_);
  ++counters_.networkRuns;
  counters_.lastNetworkMs = fused.stages.neuralMs;
  if (!fused.networkError.empty()) {
    ++counters_.networkErrors;
    // The journal hears when the network starts failing and when it works again; each failure
    // in between is counted (status), with the last error.
    if (!counters_.networkFailing)
      spdlog::error("stack {}: the network failed; stacks go on without its layers, and classes whose models need "
                    "them are not detected until it works again: {}",
                    fused.stack.id, fused.networkError);
    counters_.networkFailing = true;
    counters_.lastNetworkError = fused.networkError;
  } else if (counters_.networkFailing) {
    spdlog::info("stack {}: the network works again ({} failed runs so far)", fused.stack.id, counters_.networkErrors);
    counters_.networkFailing = false;
  }
}

void Pipeline::detectionLoop() {
  nameThisThread("fd-detect");
  // Made here: TBB observes the arena of the thread that creates the observer, and the scan's
  // helpers work in this thread's arena.
  const TbbWorkerNames helpers("fd-tbb");
  std::optional<DetectionPinning> pinning;
  if (setup_.pinDetection) {
    pinning.emplace();
    if (pinning->active()) {
      std::string list;
      for (const int c : pinning->cpus()) list += (list.empty() ? "" : " ") + std::to_string(c);
      spdlog::info("detection threads pinned, one per CPU of {} (the detection thread on CPU {})", list,
                   pinning->cpus().front());
    } else {
      spdlog::info("detection threads not pinned: {}", pinning->reason());
    }
  }
  warmUpDetection();
  const Eigen::Matrix3d K = setup_.fuser->projection().K;
  const Eigen::Isometry3d sweepToCamera = setup_.fuser->projection().sweepToCamera;
  while (!abandon_) {
    detectionBeat_ = Stamp::now().ns;
    auto fused = stackQueue_.pop(kIdleWake);
    if (!fused) {
      if (stackQueue_.closed()) break;
      continue;
    }
    const auto detector = this->detector();
    auto result = std::make_shared<StackResult>();
    result->stackId = fused->stack.id;
    result->sweepStart = fused->sweepStart;
    result->sweepEnd = fused->sweepEnd;
    result->frameStamp = fused->frameStamp;
    result->sensorStamp = std::max(fused->sweepEnd, fused->frameStamp);
    result->fuseMs = fused->fuseMs;
    result->stages = fused->stages;
    const auto t0 = std::chrono::steady_clock::now();
    result->stages.queueMs = std::chrono::duration<double, std::milli>(t0 - fused->queuedAt).count();
    try {
      const double cpu0 = threadCpuMs();
      // Without the network's layers (its run failed) only the models that do not need them run.
      std::vector<Detection> found;
      if (fused->networkError.empty()) {
        found = detector->detect(fused->stack);
      } else {
        found = detector->detectWithoutNetwork(fused->stack);
        result->networkError = fused->networkError;
        result->classesNotRun = detector->networkClasses();
      }
      result->stages.detectCpuMs = threadCpuMs() - cpu0;
      const auto t1 = std::chrono::steady_clock::now();
      result->stages.detectMs = std::chrono::duration<double, std::milli>(t1 - t0).count();
      for (Detection& d : found) {
        LocatedDetection located;
        located.position = localize(fused->stack, d.box, K, sweepToCamera);
        if (located.position) d.position = std::array<double, 3>{located.position->robot.x(), located.position->robot.y(), located.position->robot.z()};
        located.detection = std::move(d);
        result->detections.push_back(std::move(located));
      }
    } catch (const std::exception& e) {
      std::lock_guard lock(countersMutex_);
      ++counters_.detectErrors;
      spdlog::warn("detection on stack {}: {}", result->stackId, e.what());
      continue;
    }
    const auto t2 = std::chrono::steady_clock::now();
    result->detectMs = std::chrono::duration<double, std::milli>(t2 - t0).count();
    result->stages.localizeMs = result->detectMs - result->stages.detectMs;
    track(*result);
    result->stages.trackMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t2).count();
    result->detectedAt = Stamp::now();
    if (setup_.keepViews) result->view = std::make_shared<const StackView>(StackView{std::move(fused->stack), std::move(fused->sweep)});
    stackRate_.tick(result->detectedAt.ns);
    const std::size_t found = result->detections.size();
    const double detectMs = result->detectMs;
    onResult_(std::move(result));
    // Counted after the hand-over: a stack counted as detected has reached the server.
    std::lock_guard lock(countersMutex_);
    ++counters_.stacksDetected;
    counters_.detections += found;
    counters_.lastDetectMs = detectMs;
  }
  detectionDone_ = true;
}

void Pipeline::track(StackResult& result) {
  std::vector<tracking::Observation> observations;
  observations.reserve(result.detections.size());
  for (const LocatedDetection& d : result.detections) {
    tracking::Observation o;
    o.className = d.detection.className;
    if (d.position) o.position = d.position->robot;
    o.box = d.detection.box;
    observations.push_back(std::move(o));
  }
  tracking::TrackedStack tracked = tracker_.update(result.frameStamp, observations);
  for (std::size_t i = 0; i < result.detections.size(); ++i) result.detections[i].track = tracked.trackOf[i];
  result.tracks = std::move(tracked.tracks);
}

PipelineCounters Pipeline::counters() const {
  PipelineCounters c;
  {
    std::lock_guard lock(countersMutex_);
    c = counters_;
  }
  c.sensorQueue = sensorQueue_.counters();
  c.stackQueue = stackQueue_.counters();
  c.network = hasNetwork_;
  if (hasNetwork_) {
    c.networkQueue = networkQueue_.counters();
    c.networkMs = networkTimes_.summary();
  }
  const std::int64_t now = Stamp::now().ns;
  c.scanRate = scanRate_.rate(now);
  c.tiltRate = tiltRate_.rate(now);
  c.frameRate = frameRate_.rate(now);
  c.stackRate = stackRate_.rate(now);
  return c;
}

}  // namespace fusedet::daemon
