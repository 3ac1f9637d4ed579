// SPDX-License-Identifier: Apache-2.0
// fusedet replay: a sensor log through fusedetd's pipeline as fast as the machine allows, writing
// the `detections` lines a subscribed socket client would get (docs/protocol.md), one per stack,
// and with --tracks the `tracks` lines of the tracks stream.
// The work is fusedet/daemon/offline_replay.h; this file parses and prints.

#include <chrono>
#include <cstdio>
#include <fstream>
#include <memory>

#include "command.h"
#include "fusedet/daemon/offline_replay.h"
#include "fusedet/daemon/protocol.h"

namespace fusedet::tools {
namespace {

struct ReplayOptions {
  std::string log;
  std::string config;
  std::string out;
  std::string tracks;  // also the tracks lines, to this file
};

int runReplay(const ReplayOptions& o) {
  std::error_code ec;
  const auto self = std::filesystem::canonical("/proc/self/exe", ec);
  const std::filesystem::path configFile =
      o.config.empty() ? daemon::installedConfigFile(ec ? std::filesystem::path("/usr/bin/fusedet") : self)
                       : std::filesystem::path(o.config);
  const daemon::Config config = daemon::loadConfig(configFile);
  std::ofstream out(o.out, std::ios::binary | std::ios::trunc);
  if (!out) throw std::runtime_error(o.out + ": cannot open for writing");
  std::ofstream tracks;
  if (!o.tracks.empty()) {
    tracks.open(o.tracks, std::ios::binary | std::ios::trunc);
    if (!tracks) throw std::runtime_error(o.tracks + ": cannot open for writing");
  }
  const auto t0 = std::chrono::steady_clock::now();
  const daemon::OfflineReplayReport report = daemon::replayOffline(config, configFile, o.log, [&](const daemon::StackResult& r) {
    out << daemon::toLine(daemon::resultToJson(r));
    if (tracks.is_open()) tracks << daemon::toLine(daemon::tracksToJson(r));
  });
  out.flush();
  if (!out) throw std::runtime_error(o.out + ": write failed");
  if (tracks.is_open() && !tracks.flush()) throw std::runtime_error(o.tracks + ": write failed");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const daemon::PipelineCounters& c = report.counters;
  std::fprintf(stderr, "%s: %llu stacks, %llu detections in %.1f s (%.1f stacks/s); %llu unpaired sweeps, %llu errors -> %s\n",
               o.log.c_str(), static_cast<unsigned long long>(c.stacksDetected), static_cast<unsigned long long>(c.detections),
               seconds, seconds > 0 ? static_cast<double>(c.stacksDetected) / seconds : 0.0,
               static_cast<unsigned long long>(c.unpaired),
               static_cast<unsigned long long>(c.decodeErrors + c.fuseErrors + c.detectErrors), o.out.c_str());
  if (!report.damage.empty()) std::fprintf(stderr, "%s: damaged: %s\n", o.log.c_str(), report.damage.c_str());
  return 0;
}

const bool registered = registerCommand(
    "replay", "Run a sensor log through fusedetd's pipeline as fast as possible, write its detections lines", [](CLI::App& app) {
      auto o = std::make_shared<ReplayOptions>();
      app.add_option("log", o->log, "MCAP sensor log (fusedet record / synth-log)")->required()->check(CLI::ExistingFile);
      app.add_option("-c,--config", o->config,
                     "daemon config (detection, models, tracking; default: the installation's, as fusedetd)");
      app.add_option("-o,--out", o->out, "NDJSON file for the detections lines")->required();
      app.add_option("--tracks", o->tracks, "NDJSON file for the tracks lines (one per stack, as the tracks stream sends them)");
      app.footer(
          "Runs the log through the same code as fusedetd with replay.file set (the log's rig, this\n"
          "config's detection, models and tracking; fusedet/daemon/offline_replay.h), as fast as\n"
          "possible and losslessly (every stack detected), with the log's recorded stamps, and writes one\n"
          "\"detections\" line per stack, as a subscribed client gets it (docs/protocol.md; timing\n"
          "fields are this run's). Prints a summary on stderr.\n\n"
          "Examples:\n"
          "  fusedet synth-log --kitti ../shared/data/kitti --out build/logs/0005.mcap\n"
          "  fusedet replay build/logs/0005.mcap --config config/demo.yaml --out build/0005.ndjson");
      return [o] { return runReplay(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
