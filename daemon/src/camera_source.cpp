// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/camera_source.h"

#include <cmath>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "fusedet/drivers/usb/usb_devices.h"
#include "fusedet/drivers/v4l2/controls.h"
#include "fusedet/drivers/v4l2/negotiation.h"

namespace fusedet::daemon {

drivers::v4l2::CameraConfig cameraConfigFrom(const Config::Camera& camera) {
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

namespace {

std::optional<drivers::usb::UsbMatch> usbMatchFrom(const Config::Camera& camera) {
  if (camera.usb.empty()) return std::nullopt;
  auto m = drivers::usb::parseUsbMatch(camera.usb);
  if (!m) throw std::runtime_error("camera.usb: " + m.error().context);
  return *m;
}

}  // namespace

CameraSource::CameraSource(const Config::Camera& camera, drivers::usb::UsbSysfs sysfs)
    : config_(cameraConfigFrom(camera)), timing_(cameraTimingFrom(camera)), usb_(usbMatchFrom(camera)),
      sysfs_(std::move(sysfs)) {}

CameraSource::~CameraSource() { stop(); }

void CameraSource::start(SensorSink& sink) {
  stream_ = std::make_unique<drivers::v4l2::FrameStream>(
      config_, [&sink](const drivers::CameraFrame& frame) { sink.onFrame(frame); }, timing_);
  if (usb_) {
    // sysfs alone: it needs no usbfs, which the service's device sandbox does not grant.
    stream_->setDeviceResolver([match = *usb_, sysfs = sysfs_] { return drivers::usb::resolveNodeFromSysfs(sysfs, match, "video"); });
    auto* stream = stream_.get();
    auto hotplug = drivers::usb::UsbHotplug::start(
        *usb_,
        [stream](drivers::usb::HotplugEvent event, const drivers::usb::UsbDeviceInfo&) {
          if (event == drivers::usb::HotplugEvent::kArrived) stream->deviceArrived();
        },
        sysfs_);
    if (hotplug)
      hotplug_ = std::move(*hotplug);
    else
      spdlog::info("camera.usb {}: no USB hotplug events ({}); the device is looked up every 100 ms while absent",
                   usb_->toString(), hotplug.error().message());
  }
  stream_->start();
}

void CameraSource::stop() {
  if (hotplug_) hotplug_->stop();  // its callback pokes stream_
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
