// SPDX-License-Identifier: Apache-2.0
#pragma once
// FakeV4l2Device: a V4L2 capture device in memory behind the V4l2Io interface, written from the
// kernel's API documentation and sharing no code with the driver (it never calls the driver's
// negotiation, bookkeeping or fourcc helpers). Tests script what it offers and which buffers it
// returns (sequence numbers, flags, sizes, stamps), and read back the ioctls it saw.

#include <linux/videodev2.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <atomic>
#include <map>
#include <optional>
#include <mutex>
#include <set>
#include <thread>
#include <vector>

#include "fusedet/drivers/v4l2/v4l2_io.h"

namespace fusedet::testing {

struct FakeFormat {
  std::uint32_t fourcc;
  const char* description;
  std::vector<std::pair<std::uint32_t, std::uint32_t>> sizes;      // discrete
  std::vector<std::pair<std::uint32_t, std::uint32_t>> intervals;  // discrete, every size
};

struct FakeFrame {
  std::uint32_t sequence = 0;
  std::uint32_t extraFlags = 0;          // e.g. V4L2_BUF_FLAG_ERROR
  std::int64_t bytesUsed = -1;           // -1: the whole image
  std::int64_t stampNs = 1'000'000'000;  // buffer timestamp
  std::int64_t forceIndex = -1;          // >= 0: report this buffer index (a misbehaving driver)
  std::optional<timeval> rawStamp = std::nullopt;  // reported as is instead of stampNs (a misbehaving driver)
};

class FakeV4l2Device final : public drivers::v4l2::V4l2Io {
 public:
  // --- what the device is and offers (set before the camera starts) ---
  // When non-empty, open() requires this file to exist (tests remove it to "unplug").
  std::filesystem::path presenceFile;
  bool notV4l2 = false;  // VIDIOC_QUERYCAP answers ENOTTY
  std::uint32_t deviceCaps = V4L2_CAP_VIDEO_CAPTURE | V4L2_CAP_STREAMING;
  std::vector<FakeFormat> formats{
      {V4L2_PIX_FMT_YUYV, "YUYV 4:2:2", {{640, 480}, {1280, 720}}, {{1, 30}, {1, 15}}}};
  bool settableRate = true;
  std::uint32_t maxBuffers = 8;
  std::uint32_t timestampFlags = V4L2_BUF_FLAG_TIMESTAMP_MONOTONIC;
  std::map<std::uint32_t, v4l2_queryctrl> controls;
  std::map<std::uint32_t, std::set<std::uint32_t>> menus;  // valid menu indices per control

  // --- scripted stream ---
  // Before the camera runs, tests fill `script` directly; while another thread streams from the
  // device they use addFrames() and `vanished`, which are safe across threads.
  std::deque<FakeFrame> script;
  std::atomic<bool> vanished{false};  // every call fails as for an unplugged USB device
  void addFrames(const std::vector<FakeFrame>& frames) {
    std::lock_guard lock(mutex_);
    script.insert(script.end(), frames.begin(), frames.end());
  }

  // --- what it saw ---
  std::vector<unsigned long> calls;
  std::vector<std::pair<std::uint32_t, std::int32_t>> controlWrites;
  v4l2_pix_format format{};
  v4l2_fract interval{0, 0};
  bool streaming = false;
  int mapped = 0;
  std::uint32_t bufferCount = 0;
  std::deque<std::uint32_t> queued;

  std::size_t count(unsigned long request) const { return std::count(calls.begin(), calls.end(), request); }
  static std::uint8_t patternByte(std::uint32_t sequence, std::size_t offset) {
    return static_cast<std::uint8_t>((sequence * 7 + offset) & 0xFF);
  }

  fusedet::Result<void> open(const std::string& path) override {
    std::lock_guard lock(mutex_);
    if (vanished || (!presenceFile.empty() && !std::filesystem::exists(presenceFile)))
      return errnoError(ENOENT, "open");
    open_ = true;
    opened_.push_back(path);
    return {};
  }
  // Every path opened successfully, in order.
  std::vector<std::string> openedPaths() const {
    std::lock_guard lock(mutex_);
    return opened_;
  }
  void close() override {
    std::lock_guard lock(mutex_);
    // Closing the file that owns the queue frees its buffers, as the kernel does (mappings stay
    // valid until unmapped).
    open_ = false;
    streaming = false;
    queued.clear();
    bufferCount = 0;
  }
  bool isOpen() const override { return open_; }

  fusedet::Result<std::span<std::uint8_t>> map(std::size_t length, std::uint32_t offset) override {
    std::lock_guard lock(mutex_);
    const std::uint32_t index = offset / kOffsetStep;
    if (!open_ || index >= memory_.size() || length != memory_[index].size()) return errnoError(EINVAL, "mmap");
    ++mapped;
    return std::span<std::uint8_t>(memory_[index]);
  }
  void unmap(std::span<std::uint8_t>) override {
    std::lock_guard lock(mutex_);
    --mapped;
  }

  fusedet::Result<drivers::v4l2::PollResult> poll(std::chrono::milliseconds timeout) override {
    std::lock_guard lock(mutex_);
    if (vanished || !streaming) return drivers::v4l2::PollResult::kError;
    if (!script.empty() && !queued.empty()) return drivers::v4l2::PollResult::kReadable;
    std::this_thread::sleep_for(std::min(timeout, std::chrono::milliseconds(2)));
    return drivers::v4l2::PollResult::kTimeout;
  }

  int ioctl(unsigned long request, void* arg) override {
    std::lock_guard lock(mutex_);
    calls.push_back(request);
    if (!open_) return EBADF;
    if (vanished) return ENODEV;
    switch (request) {
      case VIDIOC_QUERYCAP: return queryCap(*static_cast<v4l2_capability*>(arg));
      case VIDIOC_ENUM_FMT: return enumFmt(*static_cast<v4l2_fmtdesc*>(arg));
      case VIDIOC_ENUM_FRAMESIZES: return enumSizes(*static_cast<v4l2_frmsizeenum*>(arg));
      case VIDIOC_ENUM_FRAMEINTERVALS: return enumIntervals(*static_cast<v4l2_frmivalenum*>(arg));
      case VIDIOC_S_FMT: return setFmt(*static_cast<v4l2_format*>(arg));
      case VIDIOC_G_PARM: return getParm(*static_cast<v4l2_streamparm*>(arg));
      case VIDIOC_S_PARM: return setParm(*static_cast<v4l2_streamparm*>(arg));
      case VIDIOC_QUERYCTRL: return queryCtrl(*static_cast<v4l2_queryctrl*>(arg));
      case VIDIOC_QUERYMENU: return queryMenu(*static_cast<v4l2_querymenu*>(arg));
      case VIDIOC_S_CTRL: return setCtrl(*static_cast<v4l2_control*>(arg));
      case VIDIOC_REQBUFS: return reqBufs(*static_cast<v4l2_requestbuffers*>(arg));
      case VIDIOC_QUERYBUF: return queryBuf(*static_cast<v4l2_buffer*>(arg));
      case VIDIOC_QBUF: return qBuf(*static_cast<v4l2_buffer*>(arg));
      case VIDIOC_DQBUF: return dqBuf(*static_cast<v4l2_buffer*>(arg));
      case VIDIOC_STREAMON: streaming = true; return 0;
      case VIDIOC_STREAMOFF: streaming = false; queued.clear(); return 0;
      default: return ENOTTY;
    }
  }

 private:
  static constexpr std::uint32_t kOffsetStep = 1u << 20;

  static fusedet::Error errnoError(int e, const char* what) { return fusedet::errnoError(e, what); }

  const FakeFormat* find(std::uint32_t fourcc) const {
    for (const FakeFormat& f : formats)
      if (f.fourcc == fourcc) return &f;
    return nullptr;
  }
  int queryCap(v4l2_capability& c) {
    if (notV4l2) return ENOTTY;
    std::memset(&c, 0, sizeof c);
    std::strcpy(reinterpret_cast<char*>(c.driver), "fake");
    std::strcpy(reinterpret_cast<char*>(c.card), "Fake Camera");
    std::strcpy(reinterpret_cast<char*>(c.bus_info), "platform:fake");
    c.device_caps = deviceCaps;
    c.capabilities = deviceCaps | V4L2_CAP_DEVICE_CAPS;
    return 0;
  }
  int enumFmt(v4l2_fmtdesc& d) {
    if (d.type != V4L2_BUF_TYPE_VIDEO_CAPTURE || d.index >= formats.size()) return EINVAL;
    const FakeFormat& f = formats[d.index];
    d.pixelformat = f.fourcc;
    d.flags = f.fourcc == V4L2_PIX_FMT_MJPEG ? V4L2_FMT_FLAG_COMPRESSED : 0;
    std::snprintf(reinterpret_cast<char*>(d.description), sizeof d.description, "%s", f.description);
    return 0;
  }
  int enumSizes(v4l2_frmsizeenum& s) {
    const FakeFormat* f = find(s.pixel_format);
    if (!f || s.index >= f->sizes.size()) return EINVAL;
    s.type = V4L2_FRMSIZE_TYPE_DISCRETE;
    s.discrete = {f->sizes[s.index].first, f->sizes[s.index].second};
    return 0;
  }
  int enumIntervals(v4l2_frmivalenum& v) {
    const FakeFormat* f = find(v.pixel_format);
    if (!f || v.index >= f->intervals.size()) return EINVAL;
    if (std::find(f->sizes.begin(), f->sizes.end(), std::make_pair(v.width, v.height)) == f->sizes.end()) return EINVAL;
    v.type = V4L2_FRMIVAL_TYPE_DISCRETE;
    v.discrete = {f->intervals[v.index].first, f->intervals[v.index].second};
    return 0;
  }
  int setFmt(v4l2_format& fmt) {
    if (fmt.type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return EINVAL;
    if (bufferCount > 0) return EBUSY;
    v4l2_pix_format& p = fmt.fmt.pix;
    const FakeFormat* f = find(p.pixelformat);
    if (!f) f = &formats.front();  // drivers substitute a format they have
    // Nearest offered size by summed width and height difference.
    auto best = f->sizes.front();
    auto dist = [&](std::pair<std::uint32_t, std::uint32_t> s) {
      return std::abs(static_cast<long>(s.first) - static_cast<long>(p.width)) +
             std::abs(static_cast<long>(s.second) - static_cast<long>(p.height));
    };
    for (auto s : f->sizes)
      if (dist(s) < dist(best)) best = s;
    p.pixelformat = f->fourcc;
    p.width = best.first;
    p.height = best.second;
    p.field = V4L2_FIELD_NONE;
    p.bytesperline = f->fourcc == V4L2_PIX_FMT_YUYV ? best.first * 2 : 0;
    p.sizeimage = f->fourcc == V4L2_PIX_FMT_YUYV ? best.first * best.second * 2 : best.first * best.second;
    format = p;
    return 0;
  }
  int getParm(v4l2_streamparm& p) {
    if (p.type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return EINVAL;
    p.parm.capture.capability = settableRate ? V4L2_CAP_TIMEPERFRAME : 0;
    p.parm.capture.timeperframe = interval;
    return 0;
  }
  int setParm(v4l2_streamparm& p) {
    if (!settableRate) {
      p.parm.capture.capability = 0;
      return 0;
    }
    const FakeFormat* f = find(format.pixelformat);
    if (f == nullptr || f->intervals.empty()) return EINVAL;
    const v4l2_fract want = p.parm.capture.timeperframe;
    auto best = f->intervals.front();
    auto err = [&](std::pair<std::uint32_t, std::uint32_t> i) {
      return std::abs(static_cast<double>(i.first) / i.second - static_cast<double>(want.numerator) / want.denominator);
    };
    for (auto i : f->intervals)
      if (err(i) < err(best)) best = i;
    interval = {best.first, best.second};
    p.parm.capture.timeperframe = interval;
    p.parm.capture.capability = V4L2_CAP_TIMEPERFRAME;
    return 0;
  }
  int queryCtrl(v4l2_queryctrl& q) {
    auto it = controls.find(q.id);
    if (it == controls.end()) return EINVAL;
    q = it->second;
    return 0;
  }
  int queryMenu(v4l2_querymenu& m) {
    auto it = menus.find(m.id);
    if (it == menus.end() || !it->second.count(m.index)) return EINVAL;
    std::snprintf(reinterpret_cast<char*>(m.name), sizeof m.name, "item %u", m.index);
    return 0;
  }
  int setCtrl(v4l2_control& c) {
    auto it = controls.find(c.id);
    if (it == controls.end()) return EINVAL;
    if (c.value < it->second.minimum || c.value > it->second.maximum) return ERANGE;
    controlWrites.emplace_back(c.id, c.value);
    return 0;
  }
  int reqBufs(v4l2_requestbuffers& r) {
    if (r.memory != V4L2_MEMORY_MMAP || r.type != V4L2_BUF_TYPE_VIDEO_CAPTURE) return EINVAL;
    if (r.count == 0) {
      if (mapped > 0) return EBUSY;
      memory_.clear();
      bufferCount = 0;
      return 0;
    }
    bufferCount = std::min(r.count, maxBuffers);
    r.count = bufferCount;
    memory_.assign(bufferCount, std::vector<std::uint8_t>(format.sizeimage));
    return 0;
  }
  int queryBuf(v4l2_buffer& b) {
    if (b.index >= bufferCount) return EINVAL;
    b.length = format.sizeimage;
    b.m.offset = b.index * kOffsetStep;
    return 0;
  }
  int qBuf(v4l2_buffer& b) {
    if (b.index >= bufferCount || std::find(queued.begin(), queued.end(), b.index) != queued.end()) return EINVAL;
    queued.push_back(b.index);
    return 0;
  }
  int dqBuf(v4l2_buffer& b) {
    if (!streaming) return EINVAL;
    if (script.empty() || queued.empty()) return EAGAIN;
    const FakeFrame f = script.front();
    script.pop_front();
    const std::uint32_t index = queued.front();
    queued.pop_front();
    std::vector<std::uint8_t>& mem = memory_[index];
    const std::size_t used = f.bytesUsed < 0 ? mem.size() : static_cast<std::size_t>(f.bytesUsed);
    for (std::size_t i = 0; i < std::min(used, mem.size()); ++i) mem[i] = patternByte(f.sequence, i);
    b.index = f.forceIndex >= 0 ? static_cast<std::uint32_t>(f.forceIndex) : index;
    b.bytesused = static_cast<std::uint32_t>(used);
    b.sequence = f.sequence;
    b.flags = timestampFlags | f.extraFlags;
    b.field = V4L2_FIELD_NONE;
    b.timestamp.tv_sec = f.stampNs / 1'000'000'000;
    b.timestamp.tv_usec = (f.stampNs % 1'000'000'000) / 1000;
    if (f.rawStamp) b.timestamp = *f.rawStamp;
    return 0;
  }

  mutable std::mutex mutex_;
  bool open_ = false;
  std::vector<std::string> opened_;
  std::vector<std::vector<std::uint8_t>> memory_;
};

}  // namespace fusedet::testing
