#include "fusedet/fusion/synth_log.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <memory>
#include <sstream>
#include <stdexcept>

#include "fusedet/drivers/lms291/protocol.h"
#include "fusedet/drivers/lms291/scan_decoder.h"
#include "fusedet/drivers/lms291/telegram.h"
#include "fusedet/drivers/log/recorder.h"
#include "fusedet/drivers/log/tilt_decoder.h"
#include "fusedet/fusion/frame_encode.h"
#include "fusedet/fusion/kitti.h"
#include "fusedet/fusion/synth_scene.h"

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

SynthRig::SynthRig() { nod = NodProfile{-3 * kDeg, 16 * kDeg, 15 * kDeg, 150 * kDeg}; }

std::string SynthRig::configYaml() const {
  const Eigen::Vector3d ypr = laserToCamera.linear().eulerAngles(2, 1, 0);  // R = Rz(yaw) Ry(pitch) Rx(roll)
  const Eigen::Vector3d t = laserToCamera.translation();
  std::ostringstream y;
  y << "# Rig of a log written by fusedet synth-log (config/fusedet.yaml format).\n"
    << "version: 1\n"
    << "laser:\n  device: synthetic\n  baud: " << baud << "\n  angle_deg: " << angleDeg
    << "\n  resolution_deg: " << num(resolutionCdeg / 100.0) << "\n  remission: true\n  range_unit: cm\n"
    << "  remission_full_scale: " << num(remissionFullScale) << "\n"
    << "tilt:\n  interface: can0\n  node_id: " << nodeId << "\n  min_deg: " << num(nod.min / kDeg)
    << "\n  max_deg: " << num(nod.max / kDeg) << "\n  speed_deg_s: " << num(nod.speed / kDeg)
    << "\n  counts_per_rev: " << countsPerRev << "\n  gear_ratio: " << num(gearRatio)
    << "\n  zero_offset_counts: 0\n  heartbeat_ms: " << std::lround(heartbeatS * 1000) << "\n"
    << "camera:\n  device: synthetic\n  format: yuyv\n  width: " << camera.width << "\n  height: " << camera.height
    << "\n  fps: " << std::max(1L, std::lround(cameraFps)) << "\n  calibration: log:camera.yaml\n"
    << "fusion:\n  laser_to_camera:\n    rotation_rpy_deg: [" << num(ypr[2] / kDeg) << ", " << num(ypr[1] / kDeg) << ", "
    << num(ypr[0] / kDeg) << "]\n    translation: [" << num(t.x()) << ", " << num(t.y()) << ", " << num(t.z()) << "]\n"
    << "  tilt_axis_offset: [" << num(tiltAxisOffset.x()) << ", " << num(tiltAxisOffset.y()) << ", "
    << num(tiltAxisOffset.z()) << "]\n";
  return y.str();
}

std::string SynthRig::cameraYaml() const {
  std::ostringstream y;
  y << "image_width: " << camera.width << "\nimage_height: " << camera.height << "\ncamera_name: synthetic\n"
    << "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [";
  for (int i = 0; i < 9; ++i) y << (i ? ", " : "") << num(camera.K(i / 3, i % 3));
  y << "]\ndistortion_model: plumb_bob\ndistortion_coefficients:\n  rows: 1\n  cols: 5\n  data: [0, 0, 0, 0, 0]\n";
  return y.str();
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

  const double stroke = rig.nod.halfPeriod();
  report.strokeS = stroke;
  report.seconds = stroke * options.frames;
  const std::int64_t t0 = options.start.ns;
  auto ns = [](double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); };

  drivers::mcap::WriterOptions writerOptions;
  logs::Recorder rec(out, writerOptions, std::chrono::milliseconds(0));
  rec.setRig(rig.configYaml(), rig.cameraYaml());
  std::string frames;
  for (const std::string& id : report.frameIds) frames += (frames.empty() ? "" : " ") + id;
  rec.addMetadata(logs::kRecordingMetadata,
                  {{"source", "synth-log"}, {"scene", report.scene}, {"frames", frames}, {"stroke_s", num(stroke)},
                   {"start_ns", std::to_string(t0)}, {"tolerance_deg", num(options.toleranceDeg)},
                   {"note", "one nodding stroke per frame; the scene stands still during a stroke"}});
  {
    logs::TransformMessage tf{Stamp{t0}, "laser_base", "camera", {}, {}};
    const Eigen::Isometry3d camInBase = rig.laserToCamera.inverse();
    const Eigen::Quaterniond q(camInBase.linear());
    tf.translation = {camInBase.translation().x(), camInBase.translation().y(), camInBase.translation().z()};
    tf.rotation = {q.x(), q.y(), q.z(), q.w()};
    rec.record(tf);
  }

  const lms::Variant variant{rig.angleDeg, rig.resolutionCdeg};
  const int beams = variant.beams();
  const double scanPeriod = 1.0 / lms::kMirrorHz;
  const double beamS = (rig.resolutionCdeg / 100.0 / 360.0) / lms::kMirrorHz;
  const std::int64_t byteNs = ns(lms::byteSeconds(rig.baud));
  const logs::TiltDecoderConfig units{rig.nodeId, rig.countsPerRev, rig.gearRatio, 0};
  const Eigen::Vector3d axis(0, 1, 0);  // SweepConfig's default tilt axis

  std::int64_t scanIndex = 0, syncIndex = 0, cameraIndex = 0;
  for (int k = 0; k < options.frames; ++k) {
    const double end = stroke * (k + 1);
    report.strokeStart.push_back(Stamp{t0 + ns(stroke * k)});
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
        const double tilt = rig.nod.angleAt(ts + b * beamS);
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
    // CAN: SYNC, the TPDO answering it, heartbeats.
    for (; syncIndex * rig.syncPeriodS < end; ++syncIndex) {
      const double ts = syncIndex * rig.syncPeriodS;
      const auto counts = static_cast<std::uint32_t>(units.radToCounts(rig.nod.angleAt(ts)));
      const logs::CanMessage sync{Stamp{t0 + ns(ts)}, "can0", 0x080, false, false, false, {}};
      const logs::CanMessage tpdo{Stamp{t0 + ns(ts + rig.tpdoDelayS)}, "can0", 0x180u + static_cast<std::uint32_t>(rig.nodeId),
                                  false, false, false,
                                  {static_cast<std::uint8_t>(counts), static_cast<std::uint8_t>(counts >> 8),
                                   static_cast<std::uint8_t>(counts >> 16), static_cast<std::uint8_t>(counts >> 24)}};
      events.push_back({sync.stamp.ns, 1, [sync](logs::Recorder& r) { r.record(sync); }});
      events.push_back({tpdo.stamp.ns, 1, [tpdo](logs::Recorder& r) { r.record(tpdo); }});
      report.canFrames += 2;
      const long perHeartbeat = std::lround(rig.heartbeatS / rig.syncPeriodS);
      if (syncIndex % perHeartbeat == 0) {
        const logs::CanMessage hb{Stamp{t0 + ns(ts + 2.5 * rig.tpdoDelayS)}, "can0", 0x700u + static_cast<std::uint32_t>(rig.nodeId),
                                  false, false, false, {0x05}};
        events.push_back({hb.stamp.ns, 1, [hb](logs::Recorder& r) { r.record(hb); }});
        ++report.canFrames;
      }
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
  rec.close();
  return report;
}

}  // namespace fusedet::fusion
