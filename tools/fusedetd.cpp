// SPDX-License-Identifier: Apache-2.0
// fusedetd: the fusedet service - runs the pipeline and serves detections on a Unix socket
// (docs/protocol.md). Arguments only; the service lives in daemon/ (run.h).

#include <CLI/CLI.hpp>
#include <filesystem>
#include <iostream>

#include "fusedet/boost/vector_path.h"
#include "fusedet/daemon/config.h"
#include "fusedet/daemon/run.h"

int main(int argc, char** argv) {
  CLI::App app{"fusedetd - fusedet perception service (camera + tilting laser -> detections)", "fusedetd"};
  fusedet::daemon::RunOptions options;
  std::error_code ec;
  const auto self = std::filesystem::canonical("/proc/self/exe", ec);
  options.configFile = fusedet::daemon::installedConfigFile(ec ? std::filesystem::path("/usr/bin/fusedetd") : self);
  bool checkOnly = false;
  app.add_option("-c,--config", options.configFile, "YAML configuration file")->capture_default_str();
  app.add_option("-s,--socket", options.socketPath,
                 "socket path to bind instead of socket.path (ignored under socket activation)");
  app.add_flag("--check-config", checkOnly,
               "load and validate the configuration, print the effective values, exit 0 if valid");
  app.set_version_flag("--version", std::string("fusedetd ") + FUSEDET_VERSION + "\n" + fusedet::boosting::vectorPathSummary());
  app.footer(
      "Runs sources (live: the LMS 291 on laser.device, the tilt motor on tilt.interface, the camera\n"
      "on camera.device; replay: the sensor log in replay.file), fusion and every configured class\n"
      "cascade, and serves detections as newline-delimited JSON on a Unix stream socket (docs/protocol.md;\n"
      "`fusedet query` is a client). Under systemd (Type=notify) it reports READY=1 once serving,\n"
      "STATUS= lines, and WATCHDOG=1 while its pipeline threads are alive; it takes the socket from\n"
      "socket activation when given one, else binds --socket or socket.path.\n\n"
      "Signals:\n"
      "  SIGHUP   reload the config file and the models; a bad file keeps the running configuration\n"
      "           (the log and `status` say why); clients stay connected\n"
      "  SIGTERM  stop the sources (the tilt motor brought to rest first), drain queued work,\n"
      "           flush clients, exit within 2 s: 0, or 1 if the motor did not confirm it is at rest\n\n"
      "Replay (replay.file set): the log's own rig (laser, tilt, camera, fusion sections and camera\n"
      "calibration from its metadata) with this file's detection, models and socket; paced like the\n"
      "recording (replay.realtime, replay.speed) or as fast as the pipeline takes it (nothing\n"
      "dropped, deterministic). At the end of the log (replay.at_end): exit = drain, flush clients,\n"
      "exit 0; idle = keep serving; loop = start again. `status` shows the replay's progress.\n\n"
      "Exit status: 0 after SIGTERM/SIGINT, the end of a replay with at_end exit, or a valid\n"
      "--check-config; 1 on a start-up error (bad config, missing model, log that is not MCAP),\n"
      "a stop whose tilt motor did not confirm it is at rest, or a replayed log that failed.\n\n"
      "Examples:\n"
      "  fusedetd --config /etc/fusedet/fusedet.yaml --check-config\n"
      "  fusedetd --config config/fusedet.yaml --socket /tmp/fusedet.sock\n"
      "  fusedet synth-log --out build/logs/demo.mcap && fusedetd --config config/demo.yaml --socket /tmp/demo.sock");
  CLI11_PARSE(app, argc, argv);
  if (checkOnly) {
    try {
      std::cout << fusedet::daemon::dumpConfig(fusedet::daemon::loadConfig(options.configFile));
      return 0;
    } catch (const fusedet::daemon::ConfigError& e) {
      std::cerr << "fusedetd: " << e.what() << "\n";
      return 1;
    }
  }
  return fusedet::daemon::runDaemon(options);
}
