// SPDX-License-Identifier: Apache-2.0
// libFuzzer target: a camera's answers to V4L2 as V4l2Camera parses them - VIDIOC_QUERYCAP,
// the format / frame-size / frame-interval enumerations (negotiation.h chooses among them),
// S_FMT, G_PARM / S_PARM, control queries, REQBUFS / QUERYBUF, poll and DQBUF - from a device
// whose every answer (errno and the fields the driver reads) comes from the input, after a
// config (format, size, rate, buffers) taken from its first bytes. start() may only fail with an
// error naming the device; every frame readFrame() delivers has the negotiated size and no more
// bytes than its buffer; stop() returns every mapping.

#include <linux/videodev2.h>

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <map>
#include <memory>
#include <vector>

#include "byte_source.h"
#include "fusedet/drivers/v4l2/camera.h"

namespace {

using namespace fusedet::drivers::v4l2;
using fusedet::fuzz::ByteSource;

// Answers every call from the input; once it is used up the device is gone (ENODEV), so every
// retry loop of the driver ends.
class FuzzedDevice final : public V4l2Io {
 public:
  FuzzedDevice(ByteSource& in, std::size_t& mapped) : in_(in), mapped_(mapped) {}

  fusedet::Result<void> open(const std::string&) override {
    if (const int e = status()) return fusedet::errnoError(e, "open");
    open_ = true;
    return {};
  }
  void close() override { open_ = false; }
  bool isOpen() const override { return open_; }

  int ioctl(unsigned long request, void* arg) override {
    if (const int e = status()) return e;
    switch (request) {
      case VIDIOC_QUERYCAP: {
        auto* c = static_cast<v4l2_capability*>(arg);
        c->capabilities = in_.get<std::uint32_t>();
        c->device_caps = in_.get<std::uint32_t>();
        in_.fill(c->driver);  // not NUL-terminated when all 16 bytes are set
        break;
      }
      case VIDIOC_ENUM_FMT: {
        auto* d = static_cast<v4l2_fmtdesc*>(arg);
        d->pixelformat = in_.get<std::uint32_t>();
        in_.fill(std::span<std::uint8_t>(d->description, 8));
        break;
      }
      case VIDIOC_ENUM_FRAMESIZES: {
        auto* s = static_cast<v4l2_frmsizeenum*>(arg);
        s->type = in_.byte() % 4;
        s->stepwise = {in_.get<std::uint32_t>(), in_.get<std::uint32_t>(), in_.get<std::uint32_t>(),
                       in_.get<std::uint32_t>(), in_.get<std::uint32_t>(), in_.get<std::uint32_t>()};
        if (s->type == V4L2_FRMSIZE_TYPE_DISCRETE) s->discrete = {s->stepwise.min_width, s->stepwise.max_width};
        break;
      }
      case VIDIOC_ENUM_FRAMEINTERVALS: {
        auto* v = static_cast<v4l2_frmivalenum*>(arg);
        v->type = in_.byte() % 4;
        v->stepwise = {{in_.get<std::uint32_t>(), in_.get<std::uint32_t>()},
                       {in_.get<std::uint32_t>(), in_.get<std::uint32_t>()},
                       {in_.get<std::uint32_t>(), in_.get<std::uint32_t>()}};
        if (v->type == V4L2_FRMIVAL_TYPE_DISCRETE) v->discrete = v->stepwise.min;
        break;
      }
      case VIDIOC_S_FMT: {
        auto& p = static_cast<v4l2_format*>(arg)->fmt.pix;
        if (in_.byte() & 1) p.pixelformat = in_.get<std::uint32_t>();  // else the device takes the wish
        if (in_.byte() & 1) {
          p.width = in_.get<std::uint32_t>();
          p.height = in_.get<std::uint32_t>();
        }
        p.bytesperline = in_.get<std::uint32_t>();
        p.sizeimage = in_.get<std::uint32_t>();
        break;
      }
      case VIDIOC_G_PARM: static_cast<v4l2_streamparm*>(arg)->parm.capture.capability = in_.get<std::uint32_t>(); break;
      case VIDIOC_S_PARM: {
        auto& t = static_cast<v4l2_streamparm*>(arg)->parm.capture.timeperframe;
        t = {in_.get<std::uint32_t>(), in_.get<std::uint32_t>()};
        break;
      }
      case VIDIOC_QUERYCTRL: {
        auto* q = static_cast<v4l2_queryctrl*>(arg);
        q->type = in_.byte() % 10;
        q->minimum = in_.get<std::int32_t>();
        q->maximum = in_.get<std::int32_t>();
        q->step = in_.get<std::int32_t>();
        q->default_value = in_.get<std::int32_t>();
        q->flags = in_.get<std::uint32_t>();
        break;
      }
      case VIDIOC_REQBUFS: static_cast<v4l2_requestbuffers*>(arg)->count = in_.get<std::uint32_t>(); break;
      case VIDIOC_QUERYBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        b->length = in_.get<std::uint32_t>();
        b->m.offset = in_.get<std::uint32_t>();
        break;
      }
      case VIDIOC_DQBUF: {
        auto* b = static_cast<v4l2_buffer*>(arg);
        b->index = in_.get<std::uint32_t>();
        b->bytesused = in_.get<std::uint32_t>();
        b->flags = in_.get<std::uint32_t>();
        b->sequence = in_.get<std::uint32_t>();
        b->timestamp.tv_sec = in_.get<std::int64_t>();
        b->timestamp.tv_usec = in_.get<std::int64_t>();
        break;
      }
      default: break;  // QUERYMENU, S_CTRL, QBUF, STREAMON, STREAMOFF: the status says it all
    }
    return 0;
  }

  fusedet::Result<std::span<std::uint8_t>> map(std::size_t length, std::uint32_t) override {
    if (length == 0 || length > (std::size_t{1} << 20)) return fusedet::errnoError(EINVAL, "mmap");
    buffers_[next_] = std::vector<std::uint8_t>(length, 0x80);
    mapped_ += 1;
    return std::span<std::uint8_t>(buffers_[next_++]);
  }
  void unmap(std::span<std::uint8_t> mapping) override {
    for (auto it = buffers_.begin(); it != buffers_.end(); ++it)
      if (it->second.data() == mapping.data()) {
        buffers_.erase(it);
        mapped_ -= 1;
        return;
      }
    std::abort();  // unmapping what was never mapped
  }
  fusedet::Result<PollResult> poll(std::chrono::milliseconds) override {
    if (in_.exhausted()) return PollResult::kError;
    switch (in_.byte() % 3) {
      case 0: return PollResult::kReadable;
      case 1: return PollResult::kTimeout;
      default: return PollResult::kError;
    }
  }

 private:
  // 0 (success) for most bytes; otherwise an errno a driver gives.
  int status() {
    if (in_.exhausted()) return ENODEV;
    static constexpr int kErrors[] = {EINVAL, ENOTTY, EBUSY, EAGAIN, EIO, ENODEV, ENXIO, EINTR};
    const std::uint8_t b = in_.byte();
    return b < 0xF8 ? 0 : kErrors[b - 0xF8];
  }

  ByteSource& in_;
  std::size_t& mapped_;
  bool open_ = false;
  std::map<int, std::vector<std::uint8_t>> buffers_;
  int next_ = 0;
};

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  ByteSource in(data, size);
  CameraConfig config;
  config.device = "/dev/video-fuzz";
  config.format = static_cast<FormatChoice>(in.byte() % 3);
  config.width = 16 + in.get<std::uint16_t>() % 8177;
  config.height = 16 + in.get<std::uint16_t>() % 8177;
  config.fps = 1 + in.byte() % 120;
  config.buffers = kMinBuffers + in.byte() % 29;
  std::size_t mapped = 0;
  {
    V4l2Camera camera(config, std::make_unique<FuzzedDevice>(in, mapped));
    const auto info = camera.start();
    if (!info) {
      if (info.error().message().find(config.device) == std::string::npos) std::abort();
      if (mapped != 0 || camera.streaming()) std::abort();  // a failed start leaves nothing behind
      return 0;
    }
    if (info->format.width == 0 || info->format.height == 0 || info->buffers < kMinBuffers) std::abort();
    for (int i = 0; i < 64 && !in.exhausted(); ++i) {
      const auto frame = camera.readFrame(std::chrono::milliseconds(0));
      if (!frame) {
        if (frame.error().code == std::errc::timed_out) continue;
        if (frame.error().code == std::errc::no_such_device || !camera.restartStream()) break;
        continue;
      }
      if (frame->width != static_cast<int>(info->format.width) || frame->height != static_cast<int>(info->format.height))
        std::abort();
      if (frame->format != info->format.pixelFormat || frame->bytes.empty() || frame->bytes.size() > (std::size_t{1} << 20))
        std::abort();
      if (frame->format == fusedet::drivers::PixelFormat::kYuyv &&
          frame->bytes.size() != static_cast<std::size_t>(frame->stride) * info->format.height)
        std::abort();
    }
    camera.stop();
    if (mapped != 0) std::abort();
  }
  return 0;
}
