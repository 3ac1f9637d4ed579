#pragma once
// CameraSource: the live V4L2 camera as a pipeline source. The driver's FrameStream owns the
// thread, restarts stalled streams and reopens vanished devices; each frame goes to the sink,
// which never blocks.

#include <memory>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/source.h"
#include "fusedet/drivers/v4l2/frame_stream.h"

namespace fusedet::daemon {

// The driver's configuration and timing from the config's camera section. Throws
// std::runtime_error for values the driver cannot use (format, exposure, gain, camera.usb).
drivers::v4l2::CameraConfig cameraConfigFrom(const Config::Camera& camera);
drivers::v4l2::FrameStreamTiming cameraTimingFrom(const Config::Camera& camera);

class CameraSource : public Source {
 public:
  explicit CameraSource(const Config::Camera& camera);
  ~CameraSource() override;
  void start(SensorSink& sink) override;
  void stop() override;
  std::vector<SensorHealth> health() const override;

 private:
  drivers::v4l2::CameraConfig config_;
  drivers::v4l2::FrameStreamTiming timing_;
  std::unique_ptr<drivers::v4l2::FrameStream> stream_;
};

}  // namespace fusedet::daemon
