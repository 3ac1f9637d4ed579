// fusedet log: inspect and export MCAP sensor logs (docs/log-format.md).
//   info LOG     channels, counts, time span, gaps, damage (where a cut file was cut)

#include <cstdio>

#include "command.h"
#include "fusedet/drivers/log/log_info.h"

namespace fusedet::tools {
namespace {

struct LogOptions {
  std::string file;
  double gapFactor = 3.0;
};

int runInfo(const LogOptions& o) {
  const drivers::mcap::McapReader reader(o.file);
  const drivers::logs::LogInfo info = drivers::logs::inspectLog(reader, o.gapFactor);
  std::fputs(drivers::logs::formatLogInfo(info, o.file).c_str(), stdout);
  return info.intact ? 0 : 3;
}

const bool registered = registerCommand(
    "log", "Inspect and export MCAP sensor logs (fusedet record, fusedet synth-log)", [](CLI::App& app) {
      auto o = std::make_shared<LogOptions>();
      app.require_subcommand(1);
      CLI::App* info = app.add_subcommand("info", "channels, message counts, time span, rates, gaps and damage of a log");
      info->add_option("LOG", o->file, "an MCAP file")->required();
      info->add_option("--gap-factor", o->gapFactor, "an interval longer than this many median periods counts as a gap")
          ->capture_default_str();
      app.footer(
          "info reads the whole file once, chunk by chunk, without trusting its summary: a file cut by a crash is\n"
          "read up to its last complete chunk and the report says where it was cut ('truncated cut at byte N inside\n"
          "a Chunk record starting at byte M ...'); chunks whose CRC or compression is damaged are skipped and\n"
          "listed as problems. Per channel: topic, schema, messages, span, mean rate, largest interval and the\n"
          "number of intervals longer than --gap-factor median periods.\n"
          "Examples:\n"
          "  fusedet log info run.mcap\n"
          "Exit status: 0 for an intact file; 3 when it is truncated or damaged (the report still lists what is\n"
          "readable); 1 on errors such as a missing file or one that is not MCAP ('fusedet log: error: ...').");
      return [o, info]() -> int {
        if (info->parsed()) return runInfo(*o);
        return 2;
      };
    });

}  // namespace
}  // namespace fusedet::tools
