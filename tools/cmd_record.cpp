// SPDX-License-Identifier: Apache-2.0
// fusedet record: record the live sensors into one MCAP sensor log (docs/log-format.md).

#include <atomic>
#include <chrono>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <fstream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "command.h"
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/rig.h"
#include "fusedet/drivers/canopen/socketcan_bus.h"
#include "fusedet/drivers/lms291/scan_stream.h"
#include "fusedet/drivers/log/candump.h"
#include "fusedet/drivers/log/recorder.h"
#include "fusedet/drivers/log/recording_file.h"
#include "fusedet/drivers/v4l2/frame_stream.h"

namespace fusedet::tools {
namespace {

std::atomic<bool> gStop{false};
extern "C" void onRecordSignal(int) { gStop = true; }

struct RecordOptions {
  std::string config, out, outDir;
  double duration = 0;
  bool camera = true;
  bool can = true;
};

std::string readText(const std::string& path) {
  std::ifstream in(path);
  if (!in) return {};
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

std::string utcNow() {
  const std::time_t t = std::time(nullptr);
  char b[32];
  std::strftime(b, sizeof b, "%Y-%m-%dT%H:%M:%SZ", std::gmtime(&t));
  return b;
}

int run(RecordOptions o) {
  if (o.out.empty() && o.outDir.empty()) throw std::runtime_error("give --out FILE or --out-dir DIR");
  const daemon::Config config = daemon::loadConfig(o.config);
  std::signal(SIGINT, onRecordSignal);
  std::signal(SIGTERM, onRecordSignal);
  if (!o.outDir.empty()) o.out = drivers::logs::createRecordingFile(o.outDir, std::chrono::system_clock::now()).string();
  drivers::logs::Recorder rec(o.out);  // closes a chunk every second: a crash loses at most that
  const std::string cameraYaml = readText(config.camera.calibration);
  if (cameraYaml.empty()) std::fprintf(stderr, "record: camera calibration %s not readable: not stored\n", config.camera.calibration.c_str());
  rec.setRig(readText(o.config), cameraYaml);
  rec.addMetadata(drivers::logs::kRecordingMetadata, {{"source", "record"}, {"config", o.config}, {"created", utcNow()}});
  std::atomic<std::uint64_t> scans{0};
  drivers::lms291::ScanStream laser(
      daemon::laserConfig(config),
      [&](const drivers::LaserScan& s) {
        rec.record(s);
        ++scans;
      },
      std::chrono::milliseconds(static_cast<long>(config.laser.reconnectMaxS * 1000)));
  laser.setRecorder(&rec);
  laser.start();
  std::atomic<std::uint64_t> frames{0};
  std::unique_ptr<drivers::v4l2::FrameStream> camera;
  if (o.camera) {  // the buffers as captured (YUYV/MJPEG): the frame handler gets them raw
    camera = std::make_unique<drivers::v4l2::FrameStream>(
        daemon::cameraConfig(config),
        [&](const drivers::CameraFrame& f) {
          rec.record(f);
          ++frames;
        },
        daemon::cameraTiming(config));
    camera->start();
  }
  // CAN: listen only (the daemon or `fusedet tilt` drives the motor); a missing interface is reported.
  std::atomic<std::uint64_t> canFrames{0};
  std::atomic<bool> canDone{false};
  drivers::canopen::SocketCanBus can;
  std::thread canThread;
  if (o.can) {
    if (auto r = can.open(config.tilt.interface); !r) {
      std::fprintf(stderr, "record: CAN %s not recorded: %s\n", config.tilt.interface.c_str(), r.error().message().c_str());
    } else {
      canThread = std::thread([&] {
        while (!canDone) {
          auto f = can.receive(std::chrono::milliseconds(100));
          if (f) {
            rec.record(drivers::logs::toCanMessage(*f, config.tilt.interface));
            ++canFrames;
          } else if (f.error().code != std::make_error_code(std::errc::timed_out)) {
            std::fprintf(stderr, "record: CAN %s: %s\n", config.tilt.interface.c_str(), f.error().message().c_str());
            break;
          }
        }
      });
    }
  }
  std::fprintf(stderr, "record: laser %s%s%s%s%s -> %s (Ctrl-C stops)\n", config.laser.device.c_str(),
               o.camera ? ", camera " : "", o.camera ? config.camera.device.c_str() : "", canThread.joinable() ? ", CAN " : "",
               canThread.joinable() ? config.tilt.interface.c_str() : "", o.out.c_str());
  const auto t0 = std::chrono::steady_clock::now();
  while (!gStop) {
    if (o.duration > 0 && std::chrono::steady_clock::now() - t0 > std::chrono::duration<double>(o.duration)) break;
    if (!rec.error().empty()) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  const Result<void> stopped = laser.stop();
  if (camera) camera->stop();
  canDone = true;
  if (canThread.joinable()) canThread.join();
  rec.close();  // throws on a write error
  std::printf("recorded %s: %ju messages, %ju laser scans, %ju camera frames, %ju CAN frames; laser state at stop: %s\n",
              o.out.c_str(), static_cast<std::uintmax_t>(rec.messages()), static_cast<std::uintmax_t>(scans.load()),
              static_cast<std::uintmax_t>(frames.load()), static_cast<std::uintmax_t>(canFrames.load()),
              stopped ? "stopped cleanly" : stopped.error().message().c_str());
  return scans > 0 ? 0 : 1;
}

const bool registered = registerCommand(
    "record", "Record the live sensors into one MCAP sensor log (raw bytes with stamps, decoded scans, config)",
    [](CLI::App& app) {
      auto o = std::make_shared<RecordOptions>();
      app.add_option("--config", o->config, "fusedet.yaml with the devices (laser:, camera:, tilt:)")->required();
      auto* out = app.add_option("--out", o->out, "the MCAP log to write");
      auto* outDir = app.add_option("--out-dir", o->outDir,
                                    "write a new log fusedet-<UTC start>.mcap in this folder (never an existing file)");
      out->excludes(outDir);
      outDir->excludes(out);
      app.add_option("--duration", o->duration, "stop after S seconds (0 = until Ctrl-C / SIGTERM)")->capture_default_str();
      app.add_flag("!--no-camera", o->camera, "do not record the camera");
      app.add_flag("!--no-can", o->can, "do not record the tilt motor's CAN bus");
      app.footer(
          "Records every byte read from the LMS 291's serial port with its reception stamp and line speed\n"
          "(/lms291/raw), the scans the driver decoded from them (/lms291/scan), the camera's buffers as captured\n"
          "(YUYV or MJPEG, /camera/image or /camera/compressed), the config file and the camera calibration (metadata\n"
          "fusedet.config). Both devices reconnect as the daemon's do (a missing camera is retried, not fatal). A chunk\n"
          "is closed every second, so a crash or power cut loses at most the last second; `fusedet log info` reads such\n"
          "a file up to its last complete chunk. The CAN bus of the tilt motor (tilt.interface) is recorded by\n"
          "listening only (every frame, /tilt/can): run the daemon or `fusedet tilt` to move the motor.\n"
          "Examples:\n"
          "  fusedet record --config /etc/fusedet/fusedet.yaml --out run.mcap --duration 60\n"
          "  fusedet log info run.mcap\n"
          "  fusedet record --config /etc/fusedet/fusedet.yaml --out-dir /var/lib/fusedet-recordings\n"
          "With --out-dir every start writes a file of its own, named by the UTC time it started\n"
          "(fusedet-20261202T071509Z.mcap, then -2, -3 within one second), as the packaged\n"
          "fusedet-record.service does after each restart.\n"
          "Exit status: 0 when scans were recorded; 1 on errors ('fusedet record: error: ...') or when none came.");
      return [o]() -> int { return run(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
