// SPDX-License-Identifier: Apache-2.0
#include "fusedet/sensor_logs/calib_log.h"

#include <stdexcept>
#include <string>
#include <utility>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/frame_decode.h"
#include "fusedet/fusion/pairing.h"
#include "fusedet/fusion/sweep_assembler.h"
#include "fusedet/fusion/undistorter.h"

namespace fusedet::sensor_logs {

namespace {

// Keeps every stride-th item offered; when 2 x target are kept, drops every other one and doubles
// the stride. The kept items stay evenly spread over everything offered, in bounded memory.
template <typename T>
class EvenSample {
 public:
  explicit EvenSample(std::size_t target) : target_(std::max<std::size_t>(target, 1)) {}
  void offer(T item) {
    if (offered_++ % stride_ != 0) return;
    kept_.push_back(std::move(item));
    if (kept_.size() < 2 * target_) return;
    std::vector<T> half;
    for (std::size_t i = 0; i < kept_.size(); i += 2) half.push_back(std::move(kept_[i]));
    kept_ = std::move(half);
    stride_ *= 2;
  }
  // `target` of the kept items (all if fewer), spread evenly, first and last included.
  std::vector<T> take() {
    const std::size_t n = std::min(target_, kept_.size());
    std::vector<T> out;
    for (std::size_t k = 0; k < n; ++k) out.push_back(std::move(kept_[n == 1 ? 0 : k * (kept_.size() - 1) / (n - 1)]));
    return out;
  }

 private:
  std::size_t target_, stride_ = 1, offered_ = 0;
  std::vector<T> kept_;
};

}  // namespace

LogCalibrationInput loadLogCalibrationInput(const std::filesystem::path& log, std::size_t maxFrames) {
  if (maxFrames == 0) throw std::invalid_argument("calibration needs at least one frame");
  const drivers::logs::LogSource probe(log);
  const auto rig = probe.rig();
  if (!rig) throw std::runtime_error(log.string() + ": the log carries no rig (metadata fusedet.config)");
  const daemon::Config config = daemon::parseConfig(rig->configYaml, log.string() + ":fusedet.config");
  const fusion::CameraModel camera = fusion::parseCameraModel(rig->cameraYaml, log.string() + ":camera.yaml");

  drivers::logs::SensorReplay replay(log, daemon::sensorReplayConfig(config));
  fusion::SweepAssembler sweeps(daemon::sweepConfig(config));
  fusion::FramePairer pairer(static_cast<std::int64_t>(config.fusion.maxPairSkewMs) * 1'000'000);
  EvenSample<std::pair<fusion::Sweep, drivers::CameraFrame>> sample(maxFrames);
  LogCalibrationInput in;
  auto pairDone = [&] {
    for (fusion::Sweep& s : sweeps.takeSweeps()) {
      ++in.sweeps;
      auto frame = pairer.pair(s);
      if (!frame) continue;
      ++in.paired;
      sample.offer({std::move(s), std::move(*frame)});
    }
  };
  drivers::logs::SensorReplay::Handlers h;
  h.scan = [&](const drivers::LaserScan& s) { sweeps.addScan(s); };
  h.tilt = [&](const drivers::TiltSample& t) { sweeps.addTilt(t); };
  h.frame = [&](const drivers::CameraFrame& f) { pairer.addFrame(f); };
  while (replay.step(h)) pairDone();
  sweeps.flush();
  pairDone();
  if (in.paired == 0)
    throw std::runtime_error(log.string() + ": no sweep pairs with a camera frame (" + std::to_string(in.sweeps) +
                             " sweeps assembled)");

  const fusion::Undistorter undistorter(camera);
  for (auto& [sweep, frame] : sample.take()) {
    auto bgr = fusion::decodeCameraFrame(frame);
    if (!bgr) throw std::runtime_error(log.string() + ": camera frame: " + bgr.error().message());
    fusion::CalibFrame f;
    f.name = "sweep-" + std::to_string(sweep.id);
    f.image = undistorter.undistort(*bgr).clone();
    f.sweep = std::move(sweep);
    in.frames.push_back(std::move(f));
  }
  in.K = camera.K;
  in.laserToCamera = daemon::laserToCamera(config);
  return in;
}

}  // namespace fusedet::sensor_logs
