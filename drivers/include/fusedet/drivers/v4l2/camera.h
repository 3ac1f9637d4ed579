// SPDX-License-Identifier: Apache-2.0
#pragma once
// V4l2Camera: the device layer of the V4L2 capture driver. start() opens the node, checks
// VIDIOC_QUERYCAP (single-planar video capture + streaming), negotiates format and size
// (negotiation.h), sets the frame interval and exposure/gain (controls.h), maps >= 4 buffers and
// starts streaming; readFrame() polls with a timeout, dequeues, checks the buffer against the
// bookkeeping (buffer_ring.h), stamps it (the driver's CLOCK_MONOTONIC stamp when the buffer says
// V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC, else the dequeue time, counted), counts sequence gaps
// (sequence_tracker.h), shows the raw buffer to the recording hook, copies it into a CameraFrame
// and re-queues it at once.
//
// One thread uses a V4l2Camera at a time; FrameStream (frame_stream.h) adds stall restarts and
// reconnection.

#include <chrono>
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "fusedet/core/result.h"
#include "fusedet/drivers/messages.h"
#include "fusedet/drivers/v4l2/buffer_ring.h"
#include "fusedet/drivers/v4l2/controls.h"
#include "fusedet/drivers/v4l2/negotiation.h"
#include "fusedet/drivers/v4l2/sequence_tracker.h"
#include "fusedet/drivers/v4l2/v4l2_io.h"

namespace fusedet::drivers::v4l2 {

struct CameraConfig {
  std::string device = "/dev/video0";
  FormatChoice format = FormatChoice::kYuyv;
  std::uint32_t width = 640;
  std::uint32_t height = 480;
  double fps = 15;
  std::uint32_t buffers = kMinBuffers;  // asked of VIDIOC_REQBUFS; fewer than kMinBuffers granted is an error
  ControlsConfig controls;

  std::string validate() const;  // empty when usable, else the reason
};

// What VIDIOC_QUERYCAP said.
struct Capabilities {
  std::string driver, card, busInfo;
  std::uint32_t version = 0;
  std::uint32_t deviceCaps = 0;  // the node's own capabilities (device_caps when offered)
  bool canCapture() const;       // single-planar video capture
  bool canStream() const;
  std::string describe() const;  // "video capture, streaming, ..." (for errors and `camera list`)
};

// What start() set up.
struct CameraInfo {
  Capabilities caps;
  NegotiatedFormat format;
  std::uint32_t bytesPerLine = 0;
  std::uint32_t imageSize = 0;
  Fraction interval;  // invalid: the device does not let the rate be set
  std::uint32_t buffers = 0;
  std::vector<std::string> notes;  // size/interval adjustments, controls not applied as asked
};

struct CameraCounters {
  std::uint64_t frames = 0;          // CameraFrames returned
  std::uint64_t bytes = 0;           // their payload bytes
  std::uint64_t sequenceGaps = 0;    // jumps in the driver's sequence numbers
  std::uint64_t lostFrames = 0;      // frames missing in those jumps (dropped by the driver)
  std::uint64_t sequenceResets = 0;  // the driver's counter went back without a stream restart
  std::uint64_t errorFrames = 0;     // buffers flagged V4L2_BUF_FLAG_ERROR (not delivered)
  std::uint64_t shortFrames = 0;     // empty, or less than one image of raw pixels (not delivered)
  std::uint64_t hostStamps = 0;      // frames stamped at dequeue: the driver's stamp is not monotonic (or out of range)
  std::uint64_t stampsBackwards = 0; // frames not stamped after the frame before them
  std::uint64_t timeouts = 0;        // poll timeouts
  std::uint64_t bufferErrors = 0;    // dequeue answers inconsistent with the bookkeeping
  std::uint64_t streamStarts = 0;    // VIDIOC_STREAMON done (first start and restarts)
};

// One dequeued buffer as the driver filled it, for the recording hook (valid during the call).
struct RawBuffer {
  std::span<const std::uint8_t> bytes;  // bytesused of the mapping
  Stamp stamp;
  std::uint32_t sequence = 0;  // the driver's
  std::uint32_t index = 0;
  std::uint32_t flags = 0;     // V4L2_BUF_FLAG_*
  std::uint32_t fourcc = 0;
  std::uint32_t width = 0, height = 0, bytesPerLine = 0;
};
using RawHook = std::function<void(const RawBuffer&)>;

class V4l2Camera {
 public:
  explicit V4l2Camera(CameraConfig config, std::unique_ptr<V4l2Io> io = makeKernelIo());
  ~V4l2Camera();
  V4l2Camera(const V4l2Camera&) = delete;
  V4l2Camera& operator=(const V4l2Camera&) = delete;

  // Opens, configures and starts streaming. Safe to call again after a failure or a vanished
  // device: it starts from scratch. Errors name the device.
  Result<CameraInfo> start();
  // Next frame; timed_out when none arrives within `timeout`; no_such_device when the device is gone.
  Result<CameraFrame> readFrame(std::chrono::milliseconds timeout);
  // STREAMOFF, re-queue every buffer, STREAMON (a stalled stream; the device stays open).
  Result<void> restartStream();
  // Stream off (best effort), buffers unmapped and freed, node closed.
  void stop();

  // Individual steps (start() uses them; `fusedet camera list` uses the first three).
  Result<Capabilities> open();  // open + QUERYCAP; error unless a streaming capture device
  Result<std::vector<FormatOffer>> enumerateFormats();
  Result<std::vector<IntervalRange>> enumerateIntervals(std::uint32_t fourcc, std::uint32_t width, std::uint32_t height);

  void setRawHook(RawHook hook) { rawHook_ = std::move(hook); }
  const CameraConfig& config() const { return config_; }
  // Another node for the next start() (a USB camera found under a new name); only while stopped.
  void setDevice(std::string device) { config_.device = std::move(device); }
  CameraCounters counters() const;
  bool streaming() const { return streaming_; }

 private:
  struct Mapping {
    std::span<std::uint8_t> memory;
  };
  Error fail(int err, const std::string& what) const;
  Result<void> setFormat(CameraInfo& info, const std::vector<FormatOffer>& offers);
  Result<void> setInterval(CameraInfo& info);
  void applyControls(CameraInfo& info);
  Result<void> allocateBuffers(CameraInfo& info);
  Result<void> queueAll();
  Result<void> streamOn();
  void freeBuffers();

  CameraConfig config_;
  std::unique_ptr<V4l2Io> io_;
  CameraInfo info_;
  BufferRing ring_;
  std::vector<Mapping> mappings_;
  SequenceTracker sequence_;
  CameraCounters counters_;
  std::optional<Stamp> lastStamp_;   // of the last frame returned
  std::uint64_t nextSequence_ = 0;  // CameraFrame::sequence: continues across restarts, skips lost frames
  bool streaming_ = false;
  RawHook rawHook_;
};

}  // namespace fusedet::drivers::v4l2
