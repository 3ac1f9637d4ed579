// fusedetd: the fusedet service. This build validates its configuration; the device, replay and
// socket stages are wired in by the daemon issue (see daemon/README.md).

#include <CLI/CLI.hpp>
#include <iostream>

#include "fusedet/daemon/config.h"

int main(int argc, char** argv) {
  CLI::App app{"fusedetd - fusedet perception service (camera + tilting laser -> detections)",
               "fusedetd"};
  std::string configPath = FUSEDET_DEFAULT_CONFIG;
  bool checkOnly = false;
  app.add_option("-c,--config", configPath, "YAML configuration file")->capture_default_str();
  app.add_flag("--check-config", checkOnly,
               "load and validate the configuration, print the effective values, exit 0 if valid");
  app.set_version_flag("--version", std::string("fusedetd ") + FUSEDET_VERSION);
  CLI11_PARSE(app, argc, argv);
  try {
    const auto config = fusedet::daemon::loadConfig(configPath);
    if (checkOnly) {
      std::cout << fusedet::daemon::dumpConfig(config);
      return 0;
    }
  } catch (const fusedet::daemon::ConfigError& e) {
    std::cerr << "fusedetd: " << e.what() << "\n";
    return 1;
  }
  std::cerr << "fusedetd: configuration is valid, but this build has no device or replay "
               "pipeline yet; use --check-config\n";
  return 2;
}
