#include "fusedet/daemon/camera_source.h"

#include <cmath>
#include <stdexcept>

#include "fusedet/drivers/v4l2/controls.h"
#include "fusedet/drivers/v4l2/negotiation.h"

namespace fusedet::daemon {

drivers::v4l2::CameraConfig cameraConfigFrom(const Config::Camera& camera) {
  if (!camera.usb.empty())
    throw std::runtime_error("camera.usb: fusedetd opens cameras by camera.device only; set it to the node (or a udev symlink)");
  drivers::v4l2::CameraConfig c;
  c.device = camera.device;
  const auto format = drivers::v4l2::parseFormatChoice(camera.format);
  if (!format) throw std::runtime_error("camera.format: '" + camera.format + "' is not yuyv, mjpeg or auto");
  c.format = *format;
  c.width = static_cast<std::uint32_t>(camera.width);
  c.height = static_cast<std::uint32_t>(camera.height);
  c.fps = camera.fps;
  c.buffers = static_cast<std::uint32_t>(camera.buffers);
  const auto exposure = drivers::v4l2::parseControlSetting(camera.exposure);
  const auto gain = drivers::v4l2::parseControlSetting(camera.gain);
  if (!exposure) throw std::runtime_error("camera.exposure: '" + camera.exposure + "' is not auto or a number");
  if (!gain) throw std::runtime_error("camera.gain: '" + camera.gain + "' is not auto or a number");
  c.controls.exposure = *exposure;
  c.controls.gain = *gain;
  if (const std::string why = c.validate(); !why.empty()) throw std::runtime_error("camera: " + why);
  return c;
}

drivers::v4l2::FrameStreamTiming cameraTimingFrom(const Config::Camera& camera) {
  drivers::v4l2::FrameStreamTiming t;
  t.stallLimit = std::chrono::milliseconds(camera.stallMs);
  t.reconnectMax = std::chrono::milliseconds(std::lround(camera.reconnectMaxS * 1000));
  return t;
}

CameraSource::CameraSource(const Config::Camera& camera)
    : config_(cameraConfigFrom(camera)), timing_(cameraTimingFrom(camera)) {}

CameraSource::~CameraSource() { stop(); }

void CameraSource::start(SensorSink& sink) {
  stream_ = std::make_unique<drivers::v4l2::FrameStream>(
      config_, [&sink](const drivers::CameraFrame& frame) { sink.onFrame(frame); }, timing_);
  stream_->start();
}

void CameraSource::stop() {
  if (stream_) stream_->stop();
}

std::vector<SensorHealth> CameraSource::health() const {
  SensorHealth h;
  h.name = "camera";
  if (!stream_) {
    h.state = "stopped";
    return {h};
  }
  const auto c = stream_->counters();
  h.state = std::string(drivers::toString(stream_->state()));
  h.messages = c.camera.frames;
  h.reconnects = c.reopens;
  h.lost = c.camera.lostFrames;
  h.lastError = c.lastError;
  return {h};
}

}  // namespace fusedet::daemon
