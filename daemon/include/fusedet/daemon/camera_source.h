// SPDX-License-Identifier: Apache-2.0
#pragma once
// CameraSource: the live V4L2 camera as a pipeline source. The driver's FrameStream owns the
// thread, restarts stalled streams and reopens vanished devices; each frame goes to the sink,
// which never blocks. With camera.usb (VID:PID[:SERIAL][@PORT]) the node is that USB device's
// video node, looked up in sysfs before every open, so a re-plugged camera is found under its new
// node; libusb hotplug events (where available) end the wait at once.

#include <memory>
#include <optional>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/source.h"
#include "fusedet/drivers/usb/hotplug.h"
#include "fusedet/drivers/usb/sysfs.h"
#include "fusedet/drivers/usb/usb_match.h"
#include "fusedet/drivers/v4l2/frame_stream.h"

namespace fusedet::daemon {

// The driver's configuration and timing from the config's camera section. Throws
// std::runtime_error for values the driver cannot use (format, exposure, gain, camera.usb).
// With camera.usb set, `device` is camera.device, a first guess the USB lookup replaces.
drivers::v4l2::CameraConfig cameraConfigFrom(const Config::Camera& camera);
drivers::v4l2::FrameStreamTiming cameraTimingFrom(const Config::Camera& camera);

class CameraSource : public Source {
 public:
  // `sysfs`: where camera.usb is looked up (tests pass a fake tree).
  explicit CameraSource(const Config::Camera& camera, drivers::usb::UsbSysfs sysfs = drivers::usb::UsbSysfs());
  ~CameraSource() override;
  void start(SensorSink& sink) override;
  void stop() override;
  std::vector<SensorHealth> health() const override;

 private:
  drivers::v4l2::CameraConfig config_;
  drivers::v4l2::FrameStreamTiming timing_;
  std::optional<drivers::usb::UsbMatch> usb_;
  drivers::usb::UsbSysfs sysfs_;
  std::unique_ptr<drivers::v4l2::FrameStream> stream_;
  std::unique_ptr<drivers::usb::UsbHotplug> hotplug_;  // after stream_: stopped first
};

}  // namespace fusedet::daemon
