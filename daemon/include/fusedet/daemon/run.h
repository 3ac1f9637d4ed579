// SPDX-License-Identifier: Apache-2.0
#pragma once
// runDaemon: fusedetd's life under systemd (or by hand): socket activation (sd_listen_fds) or
// binding the configured path, READY=1 once requests are served, STATUS= whenever the summary
// changes, WATCHDOG=1 only while the pipeline's threads show life, SIGHUP = reload config and
// models (a bad file keeps the old and says why), SIGTERM/SIGINT = drain and exit 0 within 2 s.

#include <filesystem>
#include <string>

namespace fusedet::daemon {

struct RunOptions {
  std::filesystem::path configFile;
  std::string socketPath;  // non-empty: overrides socket.path
};

// Returns the process exit code; errors at start-up are logged and give 1.
int runDaemon(const RunOptions& options);

}  // namespace fusedet::daemon
