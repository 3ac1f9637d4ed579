// SPDX-License-Identifier: Apache-2.0
// fusedet log: inspect and export MCAP sensor logs (docs/log-format.md).
//   info LOG                          channels, counts, time span, gaps, damage (where a cut file was cut)
//   export LOG --candump F | --png DIR | --ply DIR
//   derive IN OUT [--models M...]     IN plus the channels a viewer needs (tools/sensor_logs/log_derive.h)

#include <cstdio>

#include "command.h"
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/drivers/log/candump.h"
#include "fusedet/drivers/log/log_info.h"
#include "fusedet/sensor_logs/log_derive.h"
#include "fusedet/sensor_logs/log_export.h"
#include "model_files.h"

namespace fusedet::tools {
namespace {

struct LogOptions {
  std::string file;
  double gapFactor = 3.0;
  std::string candump, png, ply;
  std::string out;
  std::vector<std::string> models{"models"};
  bool noDetections = false;
};

int runDerive(const LogOptions& o) {
  sensor_logs::DeriveOptions d;
  if (!o.noDetections) d.models = modelFiles(o.models);
  const sensor_logs::DeriveReport r = sensor_logs::deriveLog(o.file, o.out, d);
  std::printf("derive   %s -> %s: %ju raw messages copied, %ju derived messages of the input left out\n", o.file.c_str(),
              o.out.c_str(), static_cast<std::uintmax_t>(r.copied), static_cast<std::uintmax_t>(r.dropped));
  std::printf("laser    %ju scans, %ju tilt samples (%ju transforms), %ju sweeps with %ju points\n",
              static_cast<std::uintmax_t>(r.scans), static_cast<std::uintmax_t>(r.tiltSamples),
              static_cast<std::uintmax_t>(r.transforms), static_cast<std::uintmax_t>(r.sweeps),
              static_cast<std::uintmax_t>(r.points));
  std::string classes;
  for (const std::string& c : r.classes) classes += " " + c;
  std::printf("camera   %ju frames, %ju stacks%s, %ju detections (classes:%s), %ju tracks messages\n",
              static_cast<std::uintmax_t>(r.frames), static_cast<std::uintmax_t>(r.stacks),
              r.calibrated ? "" : " (no camera calibration in the log)", static_cast<std::uintmax_t>(r.detections),
              classes.empty() ? " none" : classes.c_str(), static_cast<std::uintmax_t>(r.trackMessages));
  return 0;
}

int runInfo(const LogOptions& o) {
  const drivers::mcap::McapReader reader(o.file);
  const drivers::logs::LogInfo info = drivers::logs::inspectLog(reader, o.gapFactor);
  std::fputs(drivers::logs::formatLogInfo(info, o.file).c_str(), stdout);
  return info.intact ? 0 : 3;
}

int runExport(const LogOptions& o) {
  if (o.candump.empty() && o.png.empty() && o.ply.empty()) throw std::runtime_error("export: give --candump, --png or --ply");
  if (!o.candump.empty())
    std::printf("candump  %ju CAN frames -> %s\n", static_cast<std::uintmax_t>(drivers::logs::exportCandump(o.file, o.candump)),
                o.candump.c_str());
  if (!o.png.empty())
    std::printf("png      %ju camera frames -> %s\n", static_cast<std::uintmax_t>(sensor_logs::exportFramesPng(o.file, o.png)),
                o.png.c_str());
  if (!o.ply.empty()) {
    // Sweeps are assembled with the rig the log carries (its fusedet.config), as replay does.
    const auto rig = drivers::logs::LogSource(o.file).rig();
    const daemon::Config config = rig ? daemon::parseConfig(rig->configYaml, o.file + ":fusedet.config") : daemon::Config{};
    if (!rig) std::fprintf(stderr, "log: %s has no fusedet.config; assembling sweeps with the default rig\n", o.file.c_str());
    const std::uint64_t n = sensor_logs::exportSweepsPly(o.file, daemon::sensorReplayConfig(config), daemon::sweepConfig(config), o.ply);
    std::printf("ply      %ju sweeps -> %s\n", static_cast<std::uintmax_t>(n), o.ply.c_str());
  }
  return 0;
}

const bool registered = registerCommand(
    "log", "Inspect and export MCAP sensor logs (fusedet record, fusedet synth-log)", [](CLI::App& app) {
      auto o = std::make_shared<LogOptions>();
      app.require_subcommand(1);
      CLI::App* info = app.add_subcommand("info", "channels, message counts, time span, rates, gaps and damage of a log");
      info->add_option("LOG", o->file, "an MCAP file")->required();
      info->add_option("--gap-factor", o->gapFactor, "an interval longer than this many usual periods (90th percentile of the intervals) counts as a gap")
          ->capture_default_str();
      CLI::App* derive = app.add_subcommand("derive", "copy a log and add what a viewer shows: scans, tilt transforms, sweeps, detections");
      derive->add_option("IN", o->file, "an MCAP log with raw channels and its rig (fusedet.config)")->required();
      derive->add_option("OUT", o->out, "the MCAP log to write")->required();
      derive->add_option("--models", o->models, "model files, or folders of *.json models, to detect with")->capture_default_str();
      derive->add_flag("--no-detections", o->noDetections, "no /detections channel (no models needed)");
      CLI::App* exp = app.add_subcommand("export", "write a log's CAN frames, camera frames or sweeps in other tools' formats");
      exp->add_option("LOG", o->file, "an MCAP file")->required();
      exp->add_option("--candump", o->candump, "CAN frames as a can-utils `candump -l` log (log2asc, canplayer read it)");
      exp->add_option("--png", o->png, "camera frames as DIR/frame_<sequence>_<stamp ns>.png");
      exp->add_option("--ply", o->ply, "sweeps as DIR/sweep_<n>_<start ns>.ply (x y z remission, laser base frame)");
      app.footer(
          "info reads the whole file once, chunk by chunk, without trusting its summary: a file cut by a crash is\n"
          "read up to its last complete chunk and the report says where it was cut ('truncated cut at byte N inside\n"
          "a Chunk record starting at byte M ...'); chunks whose CRC or compression is damaged are skipped and\n"
          "listed as problems. Per channel: topic, schema, messages, span, mean rate, largest interval and the\n"
          "number of intervals longer than --gap-factor usual periods (90th percentile).\n"
          "export decodes camera frames as the live pipeline does (YUYV/MJPEG -> BGR) and takes the sweeps the log\n"
          "recorded, or assembles them from its raw laser and CAN streams with the rig in its fusedet.config.\n"
          "candump stamps are the log's CLOCK_MONOTONIC seconds.\n"
          "derive replays IN's raw channels through the live decoders, the sweep assembly, the fusion and the\n"
          "detectors, configured from the rig IN carries, and writes OUT = IN's raw channels and metadata plus\n"
          "/lms291/scan (foxglove.LaserScan, frame laser), /tilt/sample, /tf (foxglove.FrameTransform: laser_base ->\n"
          "laser at every tilt sample, laser_base -> camera with every frame), /camera/calibration\n"
          "(foxglove.CameraCalibration), /sweep/points (foxglove.PointCloud, frame laser_base), /detections\n"
          "(foxglove.ImageAnnotations on the camera image, stamped like the frame), /tracks (the tracks lines of the\n"
          "socket) and /tracks/scene (foxglove.SceneUpdate: an entity track-N per live track, frame laser_base);\n"
          "detections and tracks are fusedetd's pipeline run on IN with the models: open OUT in Foxglove to see the\n"
          "camera with its detections and the sweeps and tracks in 3D. Derived channels IN had are computed again.\n"
          "Examples:\n"
          "  fusedet log info run.mcap\n"
          "  fusedet log export run.mcap --candump tilt.log && log2asc -I tilt.log -O tilt.asc can0\n"
          "  fusedet log export run.mcap --png frames/ --ply sweeps/\n"
          "  fusedet log derive run.mcap run-view.mcap --models models/\n"
          "Exit status: 0 for an intact file (info) or a finished export; 3 when info finds the file truncated or\n"
          "damaged (the report still lists what is readable); 1 on errors ('fusedet log: error: ...').");
      return [o, info, exp, derive]() -> int {
        if (info->parsed()) return runInfo(*o);
        if (derive->parsed()) return runDerive(*o);
        if (exp->parsed()) return runExport(*o);
        return 2;
      };
    });

}  // namespace
}  // namespace fusedet::tools
