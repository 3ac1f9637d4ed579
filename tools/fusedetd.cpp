// fusedetd: the fusedet service - runs the pipeline and serves detections on a Unix socket
// (docs/protocol.md). Arguments only; the service lives in daemon/ (run.h).

#include <CLI/CLI.hpp>
#include <iostream>

#include "fusedet/daemon/config.h"
#include "fusedet/daemon/run.h"

int main(int argc, char** argv) {
  CLI::App app{"fusedetd - fusedet perception service (camera + tilting laser -> detections)", "fusedetd"};
  fusedet::daemon::RunOptions options;
  options.configFile = FUSEDET_DEFAULT_CONFIG;
  bool checkOnly = false;
  app.add_option("-c,--config", options.configFile, "YAML configuration file")->capture_default_str();
  app.add_option("-s,--socket", options.socketPath,
                 "socket path to bind instead of socket.path (ignored under socket activation)");
  app.add_flag("--check-config", checkOnly,
               "load and validate the configuration, print the effective values, exit 0 if valid");
  app.set_version_flag("--version", std::string("fusedetd ") + FUSEDET_VERSION);
  app.footer(
      "Runs sources (live: the LMS 291 on laser.device), fusion and every configured class cascade,\n"
      "and serves detections as newline-delimited JSON on a Unix stream socket (docs/protocol.md;\n"
      "`fusedet query` is a client). Under systemd (Type=notify) it reports READY=1 once serving,\n"
      "STATUS= lines, and WATCHDOG=1 while its pipeline threads are alive; it takes the socket from\n"
      "socket activation when given one, else binds --socket or socket.path.\n\n"
      "Signals:\n"
      "  SIGHUP   reload the config file and the models; a bad file keeps the running configuration\n"
      "           (the log and `status` say why); clients stay connected\n"
      "  SIGTERM  stop the sources, drain queued work, flush clients, exit 0 within 2 s\n\n"
      "Exit status: 0 after SIGTERM/SIGINT or a valid --check-config, 1 on a start-up error.\n\n"
      "Examples:\n"
      "  fusedetd --config /etc/fusedet/fusedet.yaml --check-config\n"
      "  fusedetd --config config/fusedet.yaml --socket /tmp/fusedet.sock");
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
