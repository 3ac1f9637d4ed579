// SPDX-License-Identifier: Apache-2.0
// fusedet synth-log: a realistic raw sensor log from real KITTI frames (or a procedural scene).

#include <chrono>
#include <cstdio>
#include <filesystem>

#include "command.h"
#include "data_dir.h"
#include "fusedet/fusion/synthesis/synth_log.h"
#include "fusedet/sensor_logs/log_derive.h"
#include "model_files.h"

namespace fusedet::tools {
namespace {

struct SynthCliOptions {
  std::string kitti;
  std::string out;
  bool procedural = false;
  bool derived = false;
  std::vector<std::string> models{"models"};
  fusion::SynthOptions synth;
};

int run(SynthCliOptions o) {
  namespace fs = std::filesystem;
  if (o.procedural) {
    o.synth.kitti.clear();
  } else {
    o.synth.kitti = o.kitti.empty() ? defaultDataDir() / "kitti" : fs::path(o.kitti);
    if (!fs::is_directory(o.synth.kitti / "velodyne")) {
      if (!o.kitti.empty()) throw std::runtime_error(o.kitti + ": not a KITTI directory (no velodyne/)");
      std::fprintf(stderr, "synth-log: no KITTI data at %s: using the procedural scene\n", o.synth.kitti.c_str());
      o.synth.kitti.clear();
    }
  }
  const auto t0 = std::chrono::steady_clock::now();
  // --derived: the raw log goes to a temporary file first, then `log derive` writes OUT.
  const std::vector<fs::path> models = o.derived ? modelFiles(o.models) : std::vector<fs::path>{};
  const fs::path raw = o.derived ? fs::path(o.out + ".raw.tmp") : fs::path(o.out);
  const fusion::SynthReport r = fusion::synthesizeLog(o.synth, raw);
  if (o.derived) {
    const sensor_logs::DeriveReport d = sensor_logs::deriveLog(raw, o.out, sensor_logs::DeriveOptions{models});
    fs::remove(raw);
    std::printf("derived  %ju scans, %ju sweeps (%ju points), %ju stacks, %ju detections, %ju tracks messages, %ju transforms\n",
                static_cast<std::uintmax_t>(d.scans), static_cast<std::uintmax_t>(d.sweeps), static_cast<std::uintmax_t>(d.points),
                static_cast<std::uintmax_t>(d.stacks), static_cast<std::uintmax_t>(d.detections),
                static_cast<std::uintmax_t>(d.trackMessages), static_cast<std::uintmax_t>(d.transforms));
  }
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("wrote    %s (%ju bytes) in %.2f s\n", o.out.c_str(), static_cast<std::uintmax_t>(fs::file_size(o.out)), took);
  std::printf("scene    %s\nframes  ", r.scene.c_str());
  for (const std::string& id : r.frameIds) std::printf(" %s", id.c_str());
  std::printf("\nlog      %.3f s: tilt start-up %.3f s, then %zu strokes of %.3f s\n", r.seconds, r.startupS, r.frameIds.size(),
              r.strokeS);
  std::printf("laser    %ju scans, %ju beams, %.1f %% with a return; %ju bytes in %ju reads at %d baud\n",
              static_cast<std::uintmax_t>(r.scans), static_cast<std::uintmax_t>(r.beams),
              r.beams ? 100.0 * static_cast<double>(r.hits) / static_cast<double>(r.beams) : 0.0,
              static_cast<std::uintmax_t>(r.serialBytes), static_cast<std::uintmax_t>(r.serialChunks), r.rig.baud);
  std::printf("can      %ju frames of TiltDrive and the CiA 402 motor simulator (node %d: %ju SDO requests, %ju TPDO1)\n"
              "camera   %ju YUYV frames %dx%d\n",
              static_cast<std::uintmax_t>(r.canFrames), r.rig.tilt.node, static_cast<std::uintmax_t>(r.sdoRequests),
              static_cast<std::uintmax_t>(r.tpdos), static_cast<std::uintmax_t>(r.cameraFrames), r.rig.camera.width,
              r.rig.camera.height);
  return 0;
}

const bool registered = registerCommand(
    "synth-log", "Write a realistic raw sensor log (LMS telegrams, CiA 402 CAN, YUYV camera) from KITTI frames",
    [](CLI::App& app) {
      auto o = std::make_shared<SynthCliOptions>();
      app.add_option("--kitti", o->kitti, "KITTI-layout directory (default: $FUSEDET_DATA/kitti or ../shared/data/kitti)");
      app.add_option("--out", o->out, "the MCAP log to write")->required();
      app.add_flag("--procedural", o->procedural, "ignore KITTI: a procedural scene of known geometry (ground, boxes, wall)");
      app.add_option("--frames", o->synth.frames, "strokes to synthesise, one KITTI frame each")->capture_default_str();
      app.add_option("--first", o->synth.first, "index of the first KITTI frame (-1: the first of the drive's last third)")
          ->capture_default_str();
      app.add_option("--camera-fps", o->synth.cameraFps, "camera frame rate")->capture_default_str();
      app.add_flag("--derived", o->derived,
                   "add the channels a viewer shows (as fusedet log derive): scans, tilt transforms, camera calibration, "
                   "sweeps as point clouds, detections of --models as image annotations");
      app.add_option("--models", o->models, "with --derived: model files, or folders of *.json models")->capture_default_str();
      app.add_option("--tolerance-deg", o->synth.toleranceDeg, "max angle between a beam and the Velodyne return it takes")
          ->capture_default_str();
      app.footer(
          "The log is what fusedet record would have written on a robot with this rig: a SICK LMS 291 (100 deg / 1 deg,\n"
          "range + remission telegrams, cm units) at 500 kbaud on a nodding unit (CiA 402 drive, CAN node 5, -3..16 deg\n"
          "at 15 deg/s), and KITTI's colour camera 2 (YUYV). The CAN traffic is fusedet's own tilt drive (the live CANopen\n"
          "master) against the CiA 402 motor simulator on a simulated-time bus: NMT boot-up, SDO configuration, SYNC,\n"
          "TPDO1 (position + statusword), heartbeats, set-point handshakes, the stop at the end. Laser and camera start\n"
          "with the first full sweep. Each KITTI frame is one nodding stroke (~1.5 s; the scene stands still meanwhile).\n"
          "Every beam's direction comes from its scan angle and the simulated motor's angle at its time; its range\n"
          "and remission from the nearest Velodyne return along that ray (within --tolerance-deg). The rig is stored as\n"
          "metadata fusedet.config (config.yaml, camera.yaml); replay with it reproduces the geometry. Format:\n"
          "docs/log-format.md. Without KITTI data (and with --procedural) the scene is procedural.\n"
          "Examples:\n"
          "  fusedet synth-log --out build/logs/kitti.mcap\n"
          "  fusedet synth-log --kitti ../shared/data/kitti_0009 --frames 10 --first 0 --out drive9.mcap\n"
          "  fusedet synth-log --procedural --frames 3 --out scene.mcap && fusedet log info scene.mcap\n"
          "  fusedet synth-log --derived --models models/ --out view.mcap   (open view.mcap in Foxglove)\n"
          "Exit status: 0 on success, 1 on errors ('fusedet synth-log: error: ...'). Data derived from KITTI is CC BY-NC-SA\n"
          "3.0: do not commit such logs.");
      return [o]() -> int { return run(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
