// SPDX-License-Identifier: Apache-2.0
#include "fusedet/drivers/v4l2/camera.h"

#include <linux/videodev2.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>

namespace fusedet::drivers::v4l2 {
namespace {

constexpr std::uint32_t kMaxEnumerated = 1024;  // a driver that never says EINVAL must not loop us forever
constexpr std::uint32_t kMaxBuffers = 32;       // VIDEO_MAX_FRAME

std::string fixedString(const std::uint8_t* s, std::size_t n) {
  return std::string(reinterpret_cast<const char*>(s), strnlen(reinterpret_cast<const char*>(s), n));
}

std::string fractionText(Fraction f) {
  return std::to_string(f.numerator) + "/" + std::to_string(f.denominator) + " s";
}

std::string fpsText(double fps) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", fps);
  return buf;
}

}  // namespace

std::string CameraConfig::validate() const {
  if (device.empty()) return "camera: device is empty";
  if (width < 16 || width > 8192 || height < 16 || height > 8192)
    return "camera: size " + std::to_string(width) + "x" + std::to_string(height) + " outside 16..8192";
  if (!(fps > 0 && fps <= 1000)) return "camera: fps must be in (0, 1000]";
  if (buffers < kMinBuffers || buffers > kMaxBuffers)
    return "camera: buffers " + std::to_string(buffers) + " outside " + std::to_string(kMinBuffers) + ".." + std::to_string(kMaxBuffers);
  if (!controls.exposure.automatic && controls.exposure.value <= 0) return "camera: a fixed exposure must be > 0 us";
  if (!controls.gain.automatic && controls.gain.value < 0) return "camera: a fixed gain must be >= 0";
  return {};
}

bool Capabilities::canCapture() const { return (deviceCaps & V4L2_CAP_VIDEO_CAPTURE) != 0; }
bool Capabilities::canStream() const { return (deviceCaps & V4L2_CAP_STREAMING) != 0; }

std::string Capabilities::describe() const {
  static const std::pair<std::uint32_t, const char*> kNames[] = {
      {V4L2_CAP_VIDEO_CAPTURE, "video capture"}, {V4L2_CAP_VIDEO_CAPTURE_MPLANE, "multi-planar video capture"},
      {V4L2_CAP_VIDEO_OUTPUT, "video output"},   {V4L2_CAP_VIDEO_OUTPUT_MPLANE, "multi-planar video output"},
      {V4L2_CAP_VIDEO_M2M, "memory-to-memory"},  {V4L2_CAP_VIDEO_M2M_MPLANE, "multi-planar memory-to-memory"},
      {V4L2_CAP_VBI_CAPTURE, "VBI capture"},     {V4L2_CAP_SLICED_VBI_CAPTURE, "sliced VBI capture"},
      {V4L2_CAP_RADIO, "radio"},                 {V4L2_CAP_SDR_CAPTURE, "SDR capture"},
      {V4L2_CAP_META_CAPTURE, "metadata capture"}, {V4L2_CAP_TOUCH, "touch"},
      {V4L2_CAP_READWRITE, "read/write"},        {V4L2_CAP_STREAMING, "streaming"}};
  std::string s;
  for (const auto& [bit, name] : kNames)
    if (deviceCaps & bit) s += (s.empty() ? "" : ", ") + std::string(name);
  return s.empty() ? "nothing" : s;
}

V4l2Camera::V4l2Camera(CameraConfig config, std::unique_ptr<V4l2Io> io) : config_(std::move(config)), io_(std::move(io)) {}

V4l2Camera::~V4l2Camera() { stop(); }

Error V4l2Camera::fail(int err, const std::string& what) const {
  // A vanished USB camera answers ENODEV, ENXIO or ESHUTDOWN depending on where it was caught.
  if (err == ENXIO || err == ESHUTDOWN) err = ENODEV;
  return errnoError(err, "camera " + config_.device + ": " + what);
}

CameraCounters V4l2Camera::counters() const {
  CameraCounters c = counters_;
  c.sequenceGaps = sequence_.gaps();
  c.lostFrames = sequence_.lost();
  c.sequenceResets = sequence_.resets();
  return c;
}

Result<Capabilities> V4l2Camera::open() {
  stop();
  if (auto r = io_->open(config_.device); !r)
    return Error{r.error().code, "camera " + config_.device + ": " + r.error().context};
  v4l2_capability cap{};
  if (const int err = io_->ioctl(VIDIOC_QUERYCAP, &cap); err != 0) {
    io_->close();
    if (err == ENOTTY || err == EINVAL)
      return makeError(std::errc::inappropriate_io_control_operation,
                       "camera " + config_.device + ": not a V4L2 device (VIDIOC_QUERYCAP refused)");
    return fail(err, "VIDIOC_QUERYCAP");
  }
  Capabilities c;
  c.driver = fixedString(cap.driver, sizeof cap.driver);
  c.card = fixedString(cap.card, sizeof cap.card);
  c.busInfo = fixedString(cap.bus_info, sizeof cap.bus_info);
  c.version = cap.version;
  c.deviceCaps = (cap.capabilities & V4L2_CAP_DEVICE_CAPS) ? cap.device_caps : cap.capabilities;
  const std::string who = "camera " + config_.device + " (" + c.driver + ", " + c.card + ")";
  if (!c.canCapture()) {
    io_->close();
    if (c.deviceCaps & V4L2_CAP_VIDEO_CAPTURE_MPLANE)
      return makeError(std::errc::operation_not_supported, who + ": multi-planar capture only; fusedet captures single-planar");
    return makeError(std::errc::operation_not_supported, who + ": not a video capture device (it offers: " + c.describe() + ")");
  }
  if (!c.canStream()) {
    io_->close();
    return makeError(std::errc::operation_not_supported, who + ": no streaming I/O (it offers: " + c.describe() + ")");
  }
  return c;
}

Result<std::vector<FormatOffer>> V4l2Camera::enumerateFormats() {
  std::vector<FormatOffer> offers;
  for (std::uint32_t i = 0; i < kMaxEnumerated; ++i) {
    v4l2_fmtdesc d{};
    d.index = i;
    d.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    const int err = io_->ioctl(VIDIOC_ENUM_FMT, &d);
    if (err == EINVAL) break;
    if (err != 0) return fail(err, "VIDIOC_ENUM_FMT");
    FormatOffer f;
    f.fourcc = d.pixelformat;
    f.description = fixedString(d.description, sizeof d.description);
    for (std::uint32_t j = 0; j < kMaxEnumerated; ++j) {
      v4l2_frmsizeenum s{};
      s.index = j;
      s.pixel_format = d.pixelformat;
      const int e = io_->ioctl(VIDIOC_ENUM_FRAMESIZES, &s);
      if (e == EINVAL || e == ENOTTY) break;  // end of list, or sizes not enumerated at all
      if (e != 0) return fail(e, "VIDIOC_ENUM_FRAMESIZES " + fourccToString(d.pixelformat));
      if (s.type == V4L2_FRMSIZE_TYPE_DISCRETE) {
        f.sizes.push_back(SizeRange::discrete(s.discrete.width, s.discrete.height));
        continue;
      }
      const auto& w = s.stepwise;
      const bool continuous = s.type == V4L2_FRMSIZE_TYPE_CONTINUOUS;
      f.sizes.push_back(SizeRange{w.min_width, w.max_width, continuous ? 1u : w.step_width, w.min_height, w.max_height,
                                  continuous ? 1u : w.step_height});
      break;  // a range is the only entry
    }
    offers.push_back(std::move(f));
  }
  return offers;
}

Result<std::vector<IntervalRange>> V4l2Camera::enumerateIntervals(std::uint32_t fourcc, std::uint32_t width,
                                                                  std::uint32_t height) {
  std::vector<IntervalRange> out;
  for (std::uint32_t i = 0; i < kMaxEnumerated; ++i) {
    v4l2_frmivalenum v{};
    v.index = i;
    v.pixel_format = fourcc;
    v.width = width;
    v.height = height;
    const int err = io_->ioctl(VIDIOC_ENUM_FRAMEINTERVALS, &v);
    if (err == EINVAL || err == ENOTTY) break;
    if (err != 0) return fail(err, "VIDIOC_ENUM_FRAMEINTERVALS");
    if (v.type == V4L2_FRMIVAL_TYPE_DISCRETE) {
      out.push_back(IntervalRange::discrete({v.discrete.numerator, v.discrete.denominator}));
      continue;
    }
    const auto& s = v.stepwise;
    out.push_back(IntervalRange{{s.min.numerator, s.min.denominator},
                                {s.max.numerator, s.max.denominator},
                                v.type == V4L2_FRMIVAL_TYPE_CONTINUOUS ? Fraction{} : Fraction{s.step.numerator, s.step.denominator}});
    break;
  }
  return out;
}

Result<void> V4l2Camera::setFormat(CameraInfo& info, const std::vector<FormatOffer>& offers) {
  auto chosen = negotiateFormat(config_.device, offers, CaptureRequest{config_.format, config_.width, config_.height});
  if (!chosen) return chosen.error();
  if (!chosen->sizeExact)
    info.notes.push_back("size " + std::to_string(config_.width) + "x" + std::to_string(config_.height) +
                         " is not offered; using " + std::to_string(chosen->width) + "x" + std::to_string(chosen->height));
  v4l2_format f{};
  f.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  f.fmt.pix.width = chosen->width;
  f.fmt.pix.height = chosen->height;
  f.fmt.pix.pixelformat = chosen->fourcc;
  f.fmt.pix.field = V4L2_FIELD_NONE;
  if (const int err = io_->ioctl(VIDIOC_S_FMT, &f); err != 0)
    return fail(err, err == EBUSY ? "VIDIOC_S_FMT: busy (is another program capturing?)" : "VIDIOC_S_FMT");
  if (f.fmt.pix.pixelformat != chosen->fourcc)
    return makeError(std::errc::invalid_argument, "camera " + config_.device + ": asked for " + fourccToString(chosen->fourcc) +
                                                      ", the device set " + fourccToString(f.fmt.pix.pixelformat));
  if (f.fmt.pix.width != chosen->width || f.fmt.pix.height != chosen->height)
    info.notes.push_back("the device set " + std::to_string(f.fmt.pix.width) + "x" + std::to_string(f.fmt.pix.height) +
                         " instead of " + std::to_string(chosen->width) + "x" + std::to_string(chosen->height));
  chosen->width = f.fmt.pix.width;
  chosen->height = f.fmt.pix.height;
  if (chosen->width == 0 || chosen->height == 0)
    return makeError(std::errc::invalid_argument, "camera " + config_.device + ": the device set an empty image size");
  info.format = *chosen;
  info.bytesPerLine = f.fmt.pix.bytesperline;
  info.imageSize = f.fmt.pix.sizeimage;
  if (info.format.pixelFormat == PixelFormat::kYuyv) {
    if (info.bytesPerLine == 0) info.bytesPerLine = chosen->width * 2;
    if (info.bytesPerLine < chosen->width * 2)
      return makeError(std::errc::invalid_argument, "camera " + config_.device + ": bytes per line " +
                                                        std::to_string(info.bytesPerLine) + " < 2 x width " +
                                                        std::to_string(chosen->width));
  }
  return {};
}

Result<void> V4l2Camera::setInterval(CameraInfo& info) {
  v4l2_streamparm p{};
  p.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (io_->ioctl(VIDIOC_G_PARM, &p) != 0 || !(p.parm.capture.capability & V4L2_CAP_TIMEPERFRAME)) {
    info.notes.push_back("the device does not let the frame rate be set; it runs at its own rate");
    return {};
  }
  auto offered = enumerateIntervals(info.format.fourcc, info.format.width, info.format.height);
  if (!offered) return offered.error();
  Fraction want = chooseInterval(*offered, config_.fps)
                      .value_or(Fraction{1000, static_cast<std::uint32_t>(std::lround(config_.fps * 1000))});
  p = v4l2_streamparm{};
  p.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  p.parm.capture.timeperframe = {want.numerator, want.denominator};
  if (const int err = io_->ioctl(VIDIOC_S_PARM, &p); err != 0) return fail(err, "VIDIOC_S_PARM");
  info.interval = {p.parm.capture.timeperframe.numerator, p.parm.capture.timeperframe.denominator};
  if (!info.interval.valid() || std::abs(1.0 / info.interval.value() - config_.fps) > 0.01 * config_.fps)
    info.notes.push_back("asked for " + fpsText(config_.fps) + " fps; the device runs at " +
                         (info.interval.valid() ? fractionText(info.interval) + " per frame" : std::string("an unknown rate")));
  return {};
}

void V4l2Camera::applyControls(CameraInfo& info) {
  std::map<std::uint32_t, ControlInfo> present;
  for (std::uint32_t id : controlIdsOfInterest()) {
    v4l2_queryctrl q{};
    q.id = id;
    if (io_->ioctl(VIDIOC_QUERYCTRL, &q) != 0 || (q.flags & V4L2_CTRL_FLAG_DISABLED)) continue;
    ControlInfo c;
    c.minimum = q.minimum;
    c.maximum = q.maximum;
    c.step = std::max(1, q.step);
    c.defaultValue = q.default_value;
    c.writable = !(q.flags & V4L2_CTRL_FLAG_READ_ONLY);
    if (q.type == V4L2_CTRL_TYPE_MENU || q.type == V4L2_CTRL_TYPE_INTEGER_MENU)
      for (std::int32_t i = q.minimum; i <= q.maximum && i - q.minimum < 64; ++i) {
        v4l2_querymenu m{};
        m.id = id;
        m.index = static_cast<std::uint32_t>(i);
        if (io_->ioctl(VIDIOC_QUERYMENU, &m) == 0) c.menuItems.push_back(i);
      }
    present.emplace(id, std::move(c));
  }
  ControlPlan plan = planControls(config_.controls, present);
  info.notes.insert(info.notes.end(), plan.notes.begin(), plan.notes.end());
  for (const ControlWrite& w : plan.writes) {
    v4l2_control c{};
    c.id = w.id;
    c.value = w.value;
    if (const int err = io_->ioctl(VIDIOC_S_CTRL, &c); err != 0)
      info.notes.push_back("could not set " + w.name + " to " + std::to_string(w.value) + ": " + std::strerror(err));
  }
}

Result<void> V4l2Camera::allocateBuffers(CameraInfo& info) {
  v4l2_requestbuffers rb{};
  rb.count = config_.buffers;
  rb.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  rb.memory = V4L2_MEMORY_MMAP;
  if (const int err = io_->ioctl(VIDIOC_REQBUFS, &rb); err != 0)
    return fail(err, err == EINVAL ? "VIDIOC_REQBUFS: no mmap streaming" : "VIDIOC_REQBUFS");
  ring_.reset(std::min(rb.count, kMaxBuffers));
  if (auto ok = checkGrantedBuffers(config_.device, config_.buffers, rb.count); !ok) return ok.error();
  for (std::uint32_t i = 0; i < ring_.size(); ++i) {
    v4l2_buffer b{};
    b.index = i;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (const int err = io_->ioctl(VIDIOC_QUERYBUF, &b); err != 0) return fail(err, "VIDIOC_QUERYBUF " + std::to_string(i));
    auto m = io_->map(b.length, b.m.offset);
    if (!m) return Error{m.error().code, "camera " + config_.device + ": mmap buffer " + std::to_string(i)};
    mappings_.push_back(Mapping{*m});
    ring_.setLength(i, m->size());
  }
  info.buffers = ring_.size();
  return {};
}

Result<void> V4l2Camera::queueAll() {
  for (std::uint32_t i = 0; i < ring_.size(); ++i) {
    if (ring_.isQueued(i)) continue;
    v4l2_buffer b{};
    b.index = i;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (const int err = io_->ioctl(VIDIOC_QBUF, &b); err != 0) return fail(err, "VIDIOC_QBUF " + std::to_string(i));
    if (auto r = ring_.markQueued(i); !r) return Error{r.error().code, "camera " + config_.device + ": " + r.error().context};
  }
  return {};
}

Result<void> V4l2Camera::streamOn() {
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (const int err = io_->ioctl(VIDIOC_STREAMON, &type); err != 0) return fail(err, "VIDIOC_STREAMON");
  streaming_ = true;
  sequence_.restart();  // the driver's sequence numbers start again at 0
  ++counters_.streamStarts;
  return {};
}

Result<CameraInfo> V4l2Camera::start() {
  if (const std::string why = config_.validate(); !why.empty()) return makeError(std::errc::invalid_argument, why);
  auto caps = open();
  if (!caps) return caps.error();
  CameraInfo info;
  info.caps = *caps;
  auto run = [&]() -> Result<void> {
    auto offers = enumerateFormats();
    if (!offers) return offers.error();
    if (auto r = setFormat(info, *offers); !r) return r;
    if (auto r = setInterval(info); !r) return r;
    applyControls(info);
    if (auto r = allocateBuffers(info); !r) return r;
    if (auto r = queueAll(); !r) return r;
    return streamOn();
  };
  if (auto r = run(); !r) {
    stop();
    return r.error();
  }
  info_ = info;
  return info;
}

Result<void> V4l2Camera::restartStream() {
  int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
  if (const int err = io_->ioctl(VIDIOC_STREAMOFF, &type); err != 0) return fail(err, "VIDIOC_STREAMOFF");
  streaming_ = false;
  ring_.markAllDequeued();
  if (auto r = queueAll(); !r) return r;
  return streamOn();
}

void V4l2Camera::freeBuffers() {
  for (const Mapping& m : mappings_) io_->unmap(m.memory);
  mappings_.clear();
  if (ring_.size() > 0 && io_->isOpen()) {
    // Unmapped first: the kernel refuses to free mapped buffers.
    v4l2_requestbuffers rb{};
    rb.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    rb.memory = V4L2_MEMORY_MMAP;
    (void)io_->ioctl(VIDIOC_REQBUFS, &rb);
  }
  ring_.reset(0);
}

void V4l2Camera::stop() {
  if (streaming_) {
    int type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    (void)io_->ioctl(VIDIOC_STREAMOFF, &type);  // fails harmlessly when the device is gone
    streaming_ = false;
  }
  freeBuffers();
  io_->close();
}

Result<CameraFrame> V4l2Camera::readFrame(std::chrono::milliseconds timeout) {
  if (!streaming_) return makeError(std::errc::not_connected, "camera " + config_.device + ": not streaming");
  const auto deadline = std::chrono::steady_clock::now() + timeout;
  const auto timedOut = [&] {
    ++counters_.timeouts;
    return makeError(std::errc::timed_out, "camera " + config_.device + ": no frame within " + std::to_string(timeout.count()) + " ms");
  };
  for (;;) {
    const auto left = std::max(std::chrono::milliseconds(0), std::chrono::duration_cast<std::chrono::milliseconds>(
                                                                 deadline - std::chrono::steady_clock::now()));
    auto polled = io_->poll(left);
    if (!polled) return fail(polled.error().code.value(), "poll");
    if (*polled == PollResult::kTimeout) return timedOut();
    v4l2_buffer b{};
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (const int err = io_->ioctl(VIDIOC_DQBUF, &b); err != 0) {
      if (err != EAGAIN) return fail(err, "VIDIOC_DQBUF");
      if (*polled == PollResult::kError) return fail(EIO, "poll reported an error and no buffer is ready");
      if (std::chrono::steady_clock::now() >= deadline) return timedOut();
      continue;  // woken without a buffer
    }
    if (auto r = ring_.markDequeued(b.index, b.bytesused); !r) {
      ++counters_.bufferErrors;
      return Error{r.error().code, "camera " + config_.device + ": " + r.error().context};
    }
    const SequenceTracker::Step step = sequence_.next(b.sequence);
    Stamp stamp;
    // A monotonic stamp is boot time: seconds beyond what int64 nanoseconds hold (292 years) or
    // microseconds outside a second are a broken driver's, not a time (they overflowed here).
    const bool usable = b.timestamp.tv_sec >= 0 && b.timestamp.tv_sec < INT64_MAX / 1'000'000'000 &&
                        b.timestamp.tv_usec >= 0 && b.timestamp.tv_usec < 1'000'000;
    if ((b.flags & V4L2_BUF_FLAG_TIMESTAMP_MASK) == V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC && usable) {
      stamp = Stamp{static_cast<std::int64_t>(b.timestamp.tv_sec) * 1'000'000'000 +
                    static_cast<std::int64_t>(b.timestamp.tv_usec) * 1000};
    } else {
      stamp = Stamp::now();  // the driver's clock is not ours: the dequeue time is the best we have
      ++counters_.hostStamps;
    }
    const std::span<const std::uint8_t> bytes(mappings_[b.index].memory.data(), b.bytesused);
    if (rawHook_)
      rawHook_(RawBuffer{bytes, stamp, b.sequence, b.index, b.flags, info_.format.fourcc, info_.format.width,
                         info_.format.height, info_.bytesPerLine});
    const bool raw = info_.format.pixelFormat == PixelFormat::kYuyv;
    const std::size_t image = raw ? static_cast<std::size_t>(info_.bytesPerLine) * info_.format.height : 0;
    bool deliver = true;
    if (b.flags & V4L2_BUF_FLAG_ERROR) {
      ++counters_.errorFrames;
      deliver = false;
    } else if (b.bytesused == 0 || (raw && b.bytesused < image)) {
      ++counters_.shortFrames;
      deliver = false;
    }
    CameraFrame frame;
    if (deliver) {
      frame.stamp = stamp;
      frame.width = static_cast<int>(info_.format.width);
      frame.height = static_cast<int>(info_.format.height);
      frame.stride = raw ? static_cast<int>(info_.bytesPerLine) : 0;
      frame.format = info_.format.pixelFormat;
      frame.bytes.assign(bytes.begin(), bytes.begin() + static_cast<std::ptrdiff_t>(raw ? image : bytes.size()));
    }
    // Re-queued before the frame is handed on: the driver never runs short because of a consumer.
    const std::uint32_t index = b.index;
    b = v4l2_buffer{};
    b.index = index;
    b.type = V4L2_BUF_TYPE_VIDEO_CAPTURE;
    b.memory = V4L2_MEMORY_MMAP;
    if (const int err = io_->ioctl(VIDIOC_QBUF, &b); err != 0) return fail(err, "VIDIOC_QBUF " + std::to_string(index));
    if (auto r = ring_.markQueued(index); !r) return Error{r.error().code, "camera " + config_.device + ": " + r.error().context};
    nextSequence_ += step.lost;
    const std::uint64_t sequence = nextSequence_++;
    if (!deliver) continue;
    frame.sequence = sequence;
    if (lastStamp_ && frame.stamp <= *lastStamp_) ++counters_.stampsBackwards;
    lastStamp_ = frame.stamp;
    ++counters_.frames;
    counters_.bytes += frame.bytes.size();
    return frame;
  }
}

}  // namespace fusedet::drivers::v4l2
