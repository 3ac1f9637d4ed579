// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/synthesis/synth_log.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/scan_decoder.h"
#include "fusedet/drivers/lms291/telegram.h"
#include "fusedet/drivers/log/candump.h"
#include "fusedet/drivers/log/recorder.h"
#include "nod_simulation.h"
#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/synthesis/frame_encode.h"
#include "fusedet/fusion/synthesis/synth_scene.h"

namespace fusedet::fusion {

namespace lms = drivers::lms291;
namespace logs = drivers::logs;

namespace {

constexpr double kDeg = M_PI / 180.0;
constexpr std::size_t kReadSize = 64;          // bytes per read of the USB-serial adapter
constexpr std::uint16_t kNoReturn = 8191;      // 13-bit special code: no valid value
constexpr std::uint16_t kMaxRangeCode = 8182;  // largest real value (cm): 81.82 m
constexpr std::uint8_t kStatusOk = 0x10;       // status byte of a healthy LMS (as lms291-sim)

std::string num(double v) {
  char b[40];
  std::snprintf(b, sizeof b, "%.17g", v);
  return b;
}

// A KITTI-like camera for the procedural scene (numbers of KITTI's cam 2, rounded).
void proceduralCamera(SynthRig& rig) {
  rig.camera.width = 1242;
  rig.camera.height = 375;
  rig.camera.K << 721.5, 0, 609.6, 0, 721.5, 172.9, 0, 0, 1;
  Eigen::Matrix3d r;
  r << 0, -1, 0, 0, 0, -1, 1, 0, 0;  // base (x ahead, y left, z up) -> camera (x right, y down, z ahead)
  rig.laserToCamera.linear() = r;
  rig.laserToCamera.translation() = Eigen::Vector3d(0.06, -0.08, -0.27);
}

// One message to write at `t` (events of a stroke are sorted, then written).
struct Event {
  std::int64_t t;
  int order;  // ties: serial, CAN, camera in generation order
  std::function<void(logs::Recorder&)> write;
};

}  // namespace

SynthRig::SynthRig() {
  tilt.node = 5;
  tilt.minDeg = -3;
  tilt.maxDeg = 16;
  tilt.speedDegS = 15;
  tilt.units = {4096, 50.0, 0};
  tilt.heartbeatMs = 100;
}

std::string SynthRig::configYaml() const {
  const Eigen::Vector3d ypr = laserToCamera.linear().eulerAngles(2, 1, 0);  // R = Rz(yaw) Ry(pitch) Rx(roll)
  const Eigen::Vector3d t = laserToCamera.translation();
  std::ostringstream y;
  y << "# Rig of a log written by fusedet synth-log (config/fusedet.yaml format).\n"
    << "version: 1\n"
    << "laser:\n  device: synthetic\n  baud: " << baud << "\n  angle_deg: " << angleDeg
    << "\n  resolution_deg: " << num(resolutionCdeg / 100.0) << "\n  remission: true\n  range_unit: cm\n"
    << "  remission_full_scale: " << num(remissionFullScale) << "\n"
    << "tilt:\n  interface: can0\n  node_id: " << tilt.node << "\n  min_deg: " << num(tilt.minDeg)
    << "\n  max_deg: " << num(tilt.maxDeg) << "\n  speed_deg_s: " << num(tilt.speedDegS)
    << "\n  counts_per_rev: " << tilt.units.countsPerRev << "\n  gear_ratio: " << num(tilt.units.gearRatio)
    << "\n  zero_offset_counts: " << tilt.units.zeroOffsetCounts << "\n  heartbeat_ms: " << tilt.heartbeatMs << "\n"
    << "camera:\n  device: synthetic\n  format: yuyv\n  width: " << camera.width << "\n  height: " << camera.height
    << "\n  fps: " << std::max(1L, std::lround(cameraFps)) << "\n  calibration: log:camera.yaml\n"
    << "fusion:\n  laser_to_camera:\n    rotation_rpy_deg: [" << num(ypr[2] / kDeg) << ", " << num(ypr[1] / kDeg) << ", "
    << num(ypr[0] / kDeg) << "]\n    translation: [" << num(t.x()) << ", " << num(t.y()) << ", " << num(t.z()) << "]\n"
    << "  tilt_axis_offset: [" << num(tiltAxisOffset.x()) << ", " << num(tiltAxisOffset.y()) << ", "
    << num(tiltAxisOffset.z()) << "]\n";
  return y.str();
}

std::string SynthRig::cameraYaml() const {
  CameraModel undistorted = camera;
  if (undistorted.distortion.empty()) undistorted.distortion.assign(5, 0.0);  // say "none" explicitly
  return formatCameraModel(undistorted, "synthetic", "");
}

SynthReport synthesizeLog(const SynthOptions& options, const std::filesystem::path& out) {
  if (options.frames < 1) throw std::runtime_error("synth-log: --frames must be at least 1");
  if (!(options.cameraFps > 0)) throw std::runtime_error("synth-log: --camera-fps must be positive");
  SynthReport report;
  SynthRig& rig = report.rig;
  rig.cameraFps = options.cameraFps;

  // Scenes and camera images, one per stroke.
  std::vector<std::unique_ptr<SynthScene>> scenes;
  std::vector<drivers::CameraFrame> images;
  const bool kitti = !options.kitti.empty();
  if (kitti) {
    const std::vector<std::string> ids = listKittiFrames(options.kitti);
    if (ids.empty()) throw std::runtime_error(options.kitti.string() + ": no KITTI frames");
    const int first = options.first >= 0 ? options.first : static_cast<int>(ids.size() * 2 / 3);
    if (first + options.frames > static_cast<int>(ids.size()))
      throw std::runtime_error(options.kitti.string() + ": frames " + std::to_string(first) + ".." +
                               std::to_string(first + options.frames - 1) + " requested, " + std::to_string(ids.size()) + " present");
    report.scene = "kitti " + options.kitti.string();
    for (int i = 0; i < options.frames; ++i) {
      const KittiFrame f = readKittiFrame(options.kitti, ids[static_cast<std::size_t>(first + i)]);
      if (i == 0) {
        const PinholeProjection p = kittiProjection(f.calib, f.image.cols, f.image.rows);
        rig.camera.width = p.width;
        rig.camera.height = p.height;
        rig.camera.K = p.K;
        rig.laserToCamera = p.sweepToCamera;
      }
      scenes.push_back(std::make_unique<CloudScene>(f.points, options.toleranceDeg * kDeg));
      images.push_back(encodeYuyvFrame(f.image));
      report.frameIds.push_back(f.id);
    }
  } else {
    report.scene = "procedural";
    proceduralCamera(rig);
    for (int i = 0; i < options.frames; ++i) {
      auto scene = std::make_unique<ProceduralScene>(0.5 * i);  // the boxes come 0.5 m closer per stroke
      images.push_back(encodeYuyvFrame(scene->render(rig.camera, rig.laserToCamera)));
      scenes.push_back(std::move(scene));
      report.frameIds.push_back("procedural-" + std::to_string(i));
    }
  }

  // The tilt unit: the live drive against the motor simulator. Every frame on the bus, the
  // motor's actual position at every 1 ms step, and when each move reached its target.
  namespace canopen = drivers::canopen;
  std::vector<canopen::CanFrame> can;
  std::vector<std::int64_t> pathNs;
  std::vector<double> pathRad;
  std::vector<std::int64_t> reached;  // moves: 1 = at the nearer end, 1 + k = sweep k done
  canopen::sim::NodSimulationOptions nod;
  nod.drive = rig.tilt;
  nod.sweeps = options.frames;
  nod.startSeconds = static_cast<double>(options.start.ns) * 1e-9;
  nod.onFrame = [&](const canopen::CanFrame& f) { can.push_back(f); };
  nod.onStep = [&](Stamp now, std::int32_t counts, const canopen::TiltDriveCounters& c) {
    pathNs.push_back(now.ns);
    pathRad.push_back(rig.tilt.units.toRad(counts));
    while (reached.size() < c.moves) reached.push_back(now.ns);
  };
  const auto simulated = canopen::sim::runNodSimulation(nod);
  if (!simulated) throw std::runtime_error("synth-log: tilt simulation: " + simulated.error().message());
  if (reached.size() < static_cast<std::size_t>(options.frames) + 1 || can.empty())
    throw std::runtime_error("synth-log: tilt simulation ended before " + std::to_string(options.frames) + " sweeps");
  report.canFrames = can.size();
  report.tpdos = simulated->motor.tpdos;
  report.sdoRequests = simulated->motor.sdoRequests;
  // The motor's angle at t, interpolated between its 1 ms steps.
  auto tiltAt = [&](std::int64_t t) {
    const auto it = std::upper_bound(pathNs.begin(), pathNs.end(), t);
    if (it == pathNs.begin()) return pathRad.front();
    if (it == pathNs.end()) return pathRad.back();
    const auto i = static_cast<std::size_t>(it - pathNs.begin());
    const double w = static_cast<double>(t - pathNs[i - 1]) / static_cast<double>(pathNs[i] - pathNs[i - 1]);
    return pathRad[i - 1] + w * (pathRad[i] - pathRad[i - 1]);
  };
  // Stroke k starts when the motor leaves the end it reached (after the set-point handshake):
  // scans at rest before that belong to the sweep that ended there, as SweepAssembler splits.
  for (int k = 0; k < options.frames; ++k) {
    const std::int64_t at = reached[static_cast<std::size_t>(k)];
    const double rest = tiltAt(at);
    std::size_t i = static_cast<std::size_t>(std::lower_bound(pathNs.begin(), pathNs.end(), at) - pathNs.begin());
    while (i + 1 < pathNs.size() && pathRad[i] == rest) ++i;
    report.strokeStart.push_back(Stamp{i > 0 ? pathNs[i - 1] : pathNs[i]});
  }
  report.end = Stamp{reached[static_cast<std::size_t>(options.frames)]};
  const std::int64_t t0 = report.strokeStart.front().ns;  // laser and camera start here
  report.strokeS = static_cast<double>(report.end.ns - t0) * 1e-9 / options.frames;
  report.startupS = static_cast<double>(t0 - can.front().stamp.ns) * 1e-9;
  report.seconds = static_cast<double>(can.back().stamp.ns - can.front().stamp.ns) * 1e-9;
  auto ns = [](double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); };

  drivers::mcap::WriterOptions writerOptions;
  logs::Recorder rec(out, writerOptions, std::chrono::milliseconds(0));
  rec.setRig(rig.configYaml(), rig.cameraYaml());
  std::string frames, starts;
  for (const std::string& id : report.frameIds) frames += (frames.empty() ? "" : " ") + id;
  for (const Stamp& t : report.strokeStart) starts += (starts.empty() ? "" : " ") + std::to_string(t.ns);
  rec.addMetadata(logs::kRecordingMetadata,
                  {{"source", "synth-log"}, {"scene", report.scene}, {"frames", frames}, {"stroke_s", num(report.strokeS)},
                   {"start_ns", std::to_string(t0)}, {"stroke_starts_ns", starts}, {"end_ns", std::to_string(report.end.ns)},
                   {"tolerance_deg", num(options.toleranceDeg)},
                   {"note", "one nodding sweep per frame; the scene stands still during a sweep; CAN traffic of "
                            "fusedet's TiltDrive against the CiA 402 motor simulator (start-up before start_ns)"}});
  {
    logs::TransformMessage tf{Stamp{can.front().stamp.ns}, "laser_base", "camera", {}, {}};
    const Eigen::Isometry3d camInBase = rig.laserToCamera.inverse();
    const Eigen::Quaterniond q(camInBase.linear());
    tf.translation = {camInBase.translation().x(), camInBase.translation().y(), camInBase.translation().z()};
    tf.rotation = {q.x(), q.y(), q.z(), q.w()};
    rec.record(tf);
  }
  // CAN traffic of the start-up, before any laser or camera message.
  std::size_t canIndex = 0;
  for (; canIndex < can.size() && can[canIndex].stamp.ns < t0; ++canIndex) rec.record(logs::toCanMessage(can[canIndex], "can0"));

  const lms::Variant variant{rig.angleDeg, rig.resolutionCdeg};
  const int beams = variant.beams();
  const double scanPeriod = 1.0 / lms::kMirrorHz;
  const double beamS = (rig.resolutionCdeg / 100.0 / 360.0) / lms::kMirrorHz;
  const std::int64_t byteNs = ns(lms::byteSeconds(rig.baud));
  const Eigen::Vector3d axis(0, 1, 0);  // SweepConfig's default tilt axis

  std::int64_t scanIndex = 0, cameraIndex = 0;
  for (int k = 0; k < options.frames; ++k) {
    const std::int64_t endNs = k + 1 < options.frames ? report.strokeStart[static_cast<std::size_t>(k) + 1].ns : report.end.ns;
    const double end = static_cast<double>(endNs - t0) * 1e-9;  // seconds after t0
    std::vector<Event> events;
    // Laser: scans starting inside this stroke.
    for (; scanIndex * scanPeriod < end; ++scanIndex) {
      const double ts = scanIndex * scanPeriod;
      lms::RemissionBlock block;
      block.start = 1;
      block.end = beams;
      block.countWord.count = beams;
      block.countWord.unit = lms::Unit::kCm;
      for (int b = 0; b < beams; ++b) {
        const double tilt = tiltAt(t0 + ns(ts + b * beamS));
        const double a = variant.startDeg() * kDeg + b * (rig.resolutionCdeg / 100.0) * kDeg;
        const Eigen::Matrix3d r = Eigen::AngleAxisd(tilt, axis).toRotationMatrix();
        const Eigen::Vector3d o = r * rig.tiltAxisOffset;
        const Eigen::Vector3d d = r * Eigen::Vector3d(std::sin(a), -std::cos(a), 0);
        const auto hit = scenes[static_cast<std::size_t>(k)]->cast(o, d);
        std::uint16_t code = kNoReturn, rem = 0;
        if (hit) {
          const long cm = std::lround(hit->range * 100);
          if (cm <= kMaxRangeCode) {
            code = static_cast<std::uint16_t>(cm);
            rem = static_cast<std::uint16_t>(std::lround(std::clamp(hit->remission, 0.f, 1.f) * rig.remissionFullScale));
            ++report.hits;
          }
        }
        block.ranges.push_back(code);
        block.remissions.push_back(rem);
      }
      report.beams += static_cast<std::uint64_t>(beams);
      ++report.scans;
      lms::Telegram t;
      t.address = lms::kReplyAddressBit;
      t.command = lms::kRangeRemission;
      t.data = lms::encodeRangeRemission(std::span(&block, 1));
      t.status = kStatusOk;
      const std::vector<std::uint8_t> bytes = lms::encode(t);
      const std::int64_t start = t0 + ns(ts);
      for (std::size_t at = 0; at < bytes.size(); at += kReadSize) {
        const std::size_t n = std::min(kReadSize, bytes.size() - at);
        logs::SerialChunk c{Stamp{start + static_cast<std::int64_t>(at + n) * byteNs}, "synthetic-lms291", rig.baud,
                            {bytes.begin() + static_cast<long>(at), bytes.begin() + static_cast<long>(at + n)}};
        report.serialBytes += n;
        ++report.serialChunks;
        events.push_back({c.stamp.ns, 0, [c](logs::Recorder& r) { r.record(c); }});
      }
    }
    // CAN: the simulated bus traffic of this stroke.
    for (; canIndex < can.size() && can[canIndex].stamp.ns < endNs; ++canIndex) {
      const logs::CanMessage m = logs::toCanMessage(can[canIndex], "can0");
      events.push_back({m.stamp.ns, 1, [m](logs::Recorder& r) { r.record(m); }});
    }
    // Camera.
    for (; cameraIndex / options.cameraFps < end; ++cameraIndex) {
      const drivers::CameraFrame* image = &images[static_cast<std::size_t>(k)];
      const std::int64_t t = t0 + ns(cameraIndex / options.cameraFps);
      const auto seq = static_cast<std::uint64_t>(cameraIndex);
      events.push_back({t, 2, [image, t, seq](logs::Recorder& r) {
                          drivers::CameraFrame f = *image;
                          f.stamp = Stamp{t};
                          f.sequence = seq;
                          r.record(f);
                        }});
      ++report.cameraFrames;
    }
    std::stable_sort(events.begin(), events.end(), [](const Event& a, const Event& b) { return a.t < b.t; });
    for (const Event& e : events) e.write(rec);
  }
  // The stop sequence after the last sweep.
  for (; canIndex < can.size(); ++canIndex) rec.record(logs::toCanMessage(can[canIndex], "can0"));
  rec.close();
  return report;
}

}  // namespace fusedet::fusion
