// SPDX-License-Identifier: Apache-2.0
#include "fusedet/sensor_logs/log_derive.h"

#include <algorithm>
#include <stdexcept>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/offline_replay.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/daemon/stack_channels.h"
#include "fusedet/daemon/stack_detector.h"
#include "fusedet/drivers/log/recorder.h"
#include "fusedet/drivers/log/replay.h"
#include "fusedet/fusion/camera_model.h"
#include "fusedet/fusion/pairing.h"
#include "fusedet/fusion/sweep_assembler.h"

namespace fusedet::sensor_logs {

namespace logs = drivers::logs;
namespace mcap = drivers::mcap;

namespace {

// One derived message, kept until the raw messages around it are written (OUT in time order).
struct Derived {
  std::int64_t t;
  std::string topic;
  logs::Schema schema;
  std::vector<std::uint8_t> json;
};

bool isRaw(const std::string& topic) {
  return topic == logs::topic::kLaserRaw || topic == logs::topic::kCan || topic == logs::topic::kCameraRaw ||
         topic == logs::topic::kCameraCompressed;
}

}  // namespace

DeriveReport deriveLog(const std::filesystem::path& in, const std::filesystem::path& out, const DeriveOptions& options) {
  DeriveReport report;
  const logs::LogSource probe(in);
  const auto rig = probe.rig();
  if (!rig) throw std::runtime_error(in.string() + ": no fusedet.config metadata (the rig) to replay it with");
  const daemon::Config config = daemon::parseConfig(rig->configYaml, in.string() + ":config.yaml");
  const fusion::SweepConfig sweepConfig = daemon::sweepConfig(config);
  const Eigen::Isometry3d laserToCamera = daemon::laserToCamera(config);

  std::optional<fusion::CameraModel> camera;
  if (!rig->cameraYaml.empty()) {
    camera = fusion::parseCameraModel(rig->cameraYaml, in.string() + ":camera.yaml");
    report.calibrated = true;
  }
  // The stacks' detections and tracks come from the daemon's own pipeline (offline_replay.h) with
  // the rig's config and these models: the log shows what fusedetd would send.
  daemon::Config pipelineConfig = config;
  pipelineConfig.detection.models.clear();
  for (const auto& m : options.models) pipelineConfig.detection.models.push_back(std::filesystem::absolute(m).string());
  if (!options.models.empty()) report.classes = daemon::CascadeSet(pipelineConfig.detection).classes();

  // Pass 1: replay IN and compute the derived messages.
  std::vector<Derived> derived;
  auto keep = [&](Stamp t, const char* topic, logs::Schema schema, std::vector<std::uint8_t> json) {
    derived.push_back({t.ns, topic, schema, std::move(json)});
  };
  logs::SensorReplay replay(in, daemon::sensorReplayConfig(config));
  fusion::SweepAssembler sweeps(sweepConfig);
  fusion::FramePairer pairer(static_cast<std::int64_t>(config.fusion.maxPairSkewMs) * 1'000'000);
  const Eigen::Vector3d axis = sweepConfig.tiltAxis.normalized();
  auto takeSweeps = [&] {
    for (fusion::Sweep& s : sweeps.takeSweeps()) {
      ++report.sweeps;
      report.points += s.points.size();
      keep(s.end, logs::topic::kSweep, logs::Schema::kPointCloud, logs::encode(daemon::sweepCloud(s.end, s.points)));
      if (camera && pairer.pair(s)) ++report.stacks;
    }
  };
  logs::SensorReplay::Handlers h;
  h.scan = [&](const drivers::LaserScan& s) {
    ++report.scans;
    keep(s.stamp, logs::topic::kLaserScan, logs::Schema::kLaserScan, logs::encode(s));
    sweeps.addScan(s);
  };
  h.tilt = [&](const drivers::TiltSample& t) {
    ++report.tiltSamples;
    keep(t.stamp, logs::topic::kTilt, logs::Schema::kTiltSample, logs::encode(t));
    // SweepAssembler's geometry: p_base = Rot(axis, tilt) (p_scanner + offset).
    Eigen::Isometry3d laserInBase = Eigen::Isometry3d::Identity();
    laserInBase.linear() = Eigen::AngleAxisd(t.angle, axis).toRotationMatrix();
    laserInBase.translation() = laserInBase.linear() * sweepConfig.tiltAxisOffset;
    keep(t.stamp, logs::topic::kTransforms, logs::Schema::kFrameTransform, logs::encode(daemon::frameTransform(t.stamp, daemon::kBaseFrame, daemon::kLaserFrame, laserInBase)));
    ++report.transforms;
    sweeps.addTilt(t);
  };
  h.frame = [&](const drivers::CameraFrame& f) {
    ++report.frames;
    keep(f.stamp, logs::topic::kTransforms, logs::Schema::kFrameTransform,
         logs::encode(daemon::frameTransform(f.stamp, daemon::kBaseFrame, daemon::kCameraFrame, laserToCamera.inverse())));
    ++report.transforms;
    if (camera) keep(f.stamp, logs::topic::kCameraCalibration, logs::Schema::kCameraCalibration, logs::encode(daemon::cameraCalibration(f.stamp, *camera)));
    pairer.addFrame(f);
  };
  while (replay.step(h)) takeSweeps();
  sweeps.flush();
  takeSweeps();
  if (camera && !options.models.empty()) {
    const daemon::OfflineReplayReport r = daemon::replayOffline(pipelineConfig, in, in, [&](const daemon::StackResult& stack) {
      const logs::AnnotationsMessage a = daemon::detectionAnnotations(stack);
      report.detections += a.boxes.size();
      keep(stack.frameStamp, logs::topic::kDetections, logs::Schema::kImageAnnotations, logs::encode(a));
      keep(stack.frameStamp, logs::topic::kTracks, logs::Schema::kTracks, daemon::tracksMessage(stack));
      keep(stack.frameStamp, logs::topic::kTrackScene, logs::Schema::kSceneUpdate,
           logs::encode(daemon::trackScene(stack, pipelineConfig.tracking.maxCoastS)));
      report.trackMessages += 2;
    });
    report.stacks = r.counters.stacksDetected;
  }
  std::stable_sort(derived.begin(), derived.end(), [](const Derived& a, const Derived& b) { return a.t < b.t; });

  // Pass 2: OUT = IN's metadata and raw messages, with the derived ones merged in by time.
  logs::Recorder rec(out, {}, std::chrono::milliseconds(0));
  const mcap::McapReader reader(in);
  for (const mcap::Metadata& m : reader.index().metadata) rec.addMetadata(m.name, m.entries);
  std::string models;
  for (const auto& m : options.models) {
    if (!models.empty()) models += ' ';
    models += m.string();
  }
  rec.addMetadata("fusedet.derived", {{"from", in.string()}, {"models", models},
                                      {"note", "derived channels computed by fusedet log derive from the raw channels"}});
  std::size_t next = 0;
  auto writeDerivedUntil = [&](std::int64_t t) {
    for (; next < derived.size() && derived[next].t <= t; ++next)
      rec.recordEncoded(derived[next].topic, derived[next].schema, Stamp{derived[next].t}, derived[next].json);
  };
  const mcap::LogIndex& x = reader.index();
  mcap::MessageCursor cursor = reader.messages();
  while (auto m = cursor.next()) {
    const auto ch = x.channels.find(m->channelId);
    if (ch == x.channels.end() || !isRaw(ch->second.topic)) {
      ++report.dropped;
      continue;
    }
    const auto sc = x.schemas.find(ch->second.schemaId);
    const auto schema = sc == x.schemas.end() ? std::nullopt : logs::schemaByName(sc->second.name);
    if (!schema) {
      ++report.dropped;
      continue;
    }
    writeDerivedUntil(static_cast<std::int64_t>(m->logTime));
    rec.recordEncoded(ch->second.topic, *schema, Stamp{static_cast<std::int64_t>(m->logTime)}, m->data);
    ++report.copied;
  }
  writeDerivedUntil(std::numeric_limits<std::int64_t>::max());
  rec.close();
  return report;
}

}  // namespace fusedet::sensor_logs
