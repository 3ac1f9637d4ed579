// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/run.h"

#include <poll.h>
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/sinks/systemd_sink.h>
#include <spdlog/spdlog.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <systemd/sd-daemon.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <future>
#include <thread>

#include "fusedet/daemon/service_parts.h"
#include "fusedet/daemon/server.h"
#include "fusedet/daemon/service.h"

namespace fusedet::daemon {
namespace {

// True when stderr is the journal's stream (systemd sets JOURNAL_STREAM=<device>:<inode> of it,
// systemd.exec(5)); not for a child that inherited the variable with stderr redirected.
bool stderrIsJournal() {
  const char* stream = std::getenv("JOURNAL_STREAM");
  unsigned long long dev = 0, ino = 0;
  struct stat st {};
  if (!stream || std::sscanf(stream, "%llu:%llu", &dev, &ino) != 2 || ::fstat(STDERR_FILENO, &st) != 0) return false;
  return st.st_dev == dev && st.st_ino == ino;
}

using Clock = std::chrono::steady_clock;
// Past the stop budget (Service::stopBudget: the sources' stop times - the tilt motor is brought
// to rest first - plus a drain; 0.8 s without a motor, 0.96 s with one), this much more before
// the process exits whatever is left: well under systemd's 2 s promise (docs, fusedetd --help).
constexpr auto kExitSlack = std::chrono::milliseconds(200);

void notify(const std::string& state) { sd_notify(0, state.c_str()); }

// SIGTERM: stop the sources, drain within the budget, exit. The exit status is 0 only when every
// source stopped safely: a tilt motor that did not confirm it is at rest, or a source still
// stopping at the limit, is exit 1 (systemd marks the unit failed; the log says why). A cascade
// cannot be interrupted inside a stack, so a detection thread busy in a slow one is not waited
// for past the limit: that alone exits 0 without it (nothing unsafe is left running).
int stopWithin(Service& service) {
  const auto budget = service.stopBudget();
  const auto limit = budget + kExitSlack;
  std::promise<std::string> done;
  auto stopped = done.get_future();
  std::thread stopper([&service, &done, budget] { done.set_value(service.stop(Clock::now() + budget)); });
  if (stopped.wait_for(limit) == std::future_status::ready) {
    stopper.join();
    const std::string problems = stopped.get();
    if (problems.empty()) return 0;
    spdlog::error("stop: {}", problems);
    return 1;
  }
  std::fflush(nullptr);
  if (!service.sourcesStopped()) {
    spdlog::error("stop: a source was still stopping after {} ms (the tilt motor may not be at rest); exiting 1",
                  limit.count());
    std::fflush(nullptr);
    std::_Exit(1);
  }
  spdlog::warn("stop: not drained after {} ms (a pipeline thread is still inside a stack); exiting without it",
               limit.count());
  std::fflush(nullptr);
  std::_Exit(0);
}

// The socket systemd passed (socket activation), or one bound at `path`.
drivers::UniqueFd listenerFor(const std::string& path, const SocketAccess& access) {
  const int n = sd_listen_fds(1);
  if (n < 0) throw std::runtime_error(std::string("sd_listen_fds: ") + strerror(-n));
  if (n > 1) throw std::runtime_error("socket activation passed " + std::to_string(n) + " sockets; expected 1");
  if (n == 1) {
    if (sd_is_socket_unix(SD_LISTEN_FDS_START, SOCK_STREAM, 1, nullptr, 0) <= 0)
      throw std::runtime_error("socket activation: the passed fd is not a listening Unix stream socket");
    checkPassedSocket(SD_LISTEN_FDS_START, access);
    spdlog::info("serving on the socket systemd passed");
    return drivers::UniqueFd(SD_LISTEN_FDS_START);
  }
  auto fd = bindUnixSocket(path, access);
  spdlog::info("serving on {}", path);
  return fd;
}

}  // namespace

int runDaemon(const RunOptions& options) {
  // Signals are taken from a signalfd; block them before any thread exists so none inherits them.
  sigset_t signals;
  sigemptyset(&signals);
  sigaddset(&signals, SIGTERM);
  sigaddset(&signals, SIGINT);
  sigaddset(&signals, SIGHUP);
  pthread_sigmask(SIG_BLOCK, &signals, nullptr);
  signal(SIGPIPE, SIG_IGN);
  // Log lines go to stderr; stdout stays free. Under systemd they go to the journal directly, each
  // with its level as PRIORITY (error 3, warn 4, info 6, ...) and SYSLOG_IDENTIFIER=fusedetd.
  if (stderrIsJournal()) {
    spdlog::set_default_logger(spdlog::systemd_logger_mt("fusedetd", "fusedetd"));
  } else {
    spdlog::set_default_logger(spdlog::stderr_color_mt("fusedetd"));
    spdlog::set_pattern("%^%l%$: %v");
  }
  drivers::UniqueFd sigfd(signalfd(-1, &signals, SFD_CLOEXEC));
  if (!sigfd.valid()) {
    // Without it SIGTERM and SIGHUP (blocked above) would never be seen: refuse to run.
    const std::string why = std::string("signalfd: ") + std::strerror(errno) + " (SIGTERM/SIGHUP could not be handled)";
    spdlog::error("{}", why);
    notify("STATUS=failed: " + why);
    return 1;
  }

  std::unique_ptr<Service> service;
  bool exitAtEnd = false;  // replay.at_end: exit
  try {
    Config config = loadConfig(options.configFile);
    if (!options.socketPath.empty()) config.socket.path = options.socketPath;
    spdlog::set_level(spdlog::level::from_str(config.logLevel));
    const std::string socketPath = config.socket.path;
    const SocketAccess access = socketAccessFrom(config);
    (void)serverLimitsFrom(config);  // its groups exist: checked before anything is bound
    exitAtEnd = !config.replay.file.empty() && config.replay.atEnd == "exit";
    ServiceParts parts = serviceParts(std::move(config), options.configFile);
    parts.listener = listenerFor(socketPath, access);  // last: nothing is bound when the set-up fails
    service = std::make_unique<Service>(std::move(parts));
    service->start();
  } catch (const std::exception& e) {
    spdlog::error("{}", e.what());
    notify(std::string("STATUS=failed: ") + e.what());
    return 1;
  }

  std::uint64_t watchdogUs = 0;
  if (sd_watchdog_enabled(0, &watchdogUs) <= 0) watchdogUs = 0;
  // Ping at half the watchdog period; a thread whose beat is older than that is stalled.
  const auto maxAgeNs = static_cast<std::int64_t>(watchdogUs ? watchdogUs * 500 : 5'000'000'000ULL);
  const int tickMs = watchdogUs ? static_cast<int>(std::max<std::uint64_t>(50, std::min<std::uint64_t>(watchdogUs / 4000, 1000))) : 1000;
  std::string shown = service->summary();
  bool wasAlive = true;
  notify("READY=1\nSTATUS=" + shown);
  spdlog::info("ready: {}", shown);

  for (;;) {
    pollfd pfd{sigfd.get(), POLLIN, 0};
    const int n = ::poll(&pfd, 1, tickMs);
    if (n > 0) {
      signalfd_siginfo info{};
      if (::read(sigfd.get(), &info, sizeof info) == static_cast<ssize_t>(sizeof info)) {
        if (info.ssi_signo == SIGHUP) {
          notify("RELOADING=1");
          const std::string error = service->reload();
          if (error.empty()) spdlog::info("reloaded {}", options.configFile.string());
          else spdlog::error("reload failed, keeping the running configuration: {}", error);
          shown = service->summary();
          notify("READY=1\nSTATUS=" + shown);
        } else {
          spdlog::info("signal {}: draining and stopping", info.ssi_signo);
          notify("STOPPING=1\nSTATUS=stopping");
          return stopWithin(*service);
        }
      }
    }
    // A stuck thread withholds WATCHDOG=1 (systemd restarts the service after WatchdogSec) and
    // is named in STATUS= and the log meanwhile; pings resume if it recovers first.
    const std::string stuck = service->stalled(maxAgeNs);
    if (watchdogUs && stuck.empty()) notify("WATCHDOG=1");
    if (stuck.empty() != wasAlive) {
      wasAlive = stuck.empty();
      if (wasAlive) spdlog::info("watchdog: every pipeline thread shows life again");
      else spdlog::warn("watchdog: {}{}", stuck, watchdogUs ? "; WATCHDOG=1 withheld" : "");
    }
    if (exitAtEnd && service->finished()) {
      spdlog::info("end of the replayed log: flushing clients and stopping");
      notify("STOPPING=1\nSTATUS=replay finished");
      const std::string problems = service->stop(Clock::now() + service->stopBudget());
      if (!problems.empty()) spdlog::error("stop: {}", problems);
      // A log that failed under the replay is no successful end either.
      return problems.empty() && !service->failed() ? 0 : 1;
    }
    if (std::string now = service->summary() + (stuck.empty() ? "" : "; " + stuck); now != shown) {
      shown = std::move(now);
      notify("STATUS=" + shown);
    }
  }
}

}  // namespace fusedet::daemon
