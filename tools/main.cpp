// SPDX-License-Identifier: Apache-2.0
// fusedet: the command line of the fusedet perception system (see `fusedet --help`).

#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>

#include <exception>
#include <iostream>
#include <algorithm>
#include <map>
#include <memory>
#include <sstream>

#include "command.h"
#include "fusedet/boost/vector_path.h"

namespace fusedet::tools {

namespace {
std::vector<Command>& registry() {
  static std::vector<Command> commands;
  return commands;
}
}  // namespace

bool registerCommand(std::string name, std::string description, CommandSetup setup) {
  registry().push_back(Command{std::move(name), std::move(description), std::move(setup)});
  return true;
}

const std::vector<Command>& commands() { return registry(); }

namespace {
// `fusedet --help` lists each subcommand on one line: its registered description. A command's
// setup may replace its description with the long explanation; that one shows in `fusedet NAME
// --help` only.
class CommandListFormatter : public CLI::Formatter {
 public:
  void summary(const CLI::App* sub, std::string text) { summaries_[sub] = std::move(text); }
  std::string make_subcommand(const CLI::App* sub) const override {
    const auto it = summaries_.find(sub);
    if (it == summaries_.end()) return CLI::Formatter::make_subcommand(sub);
    std::stringstream out;
    CLI::detail::format_help(out, sub->get_display_name(true), it->second, get_column_width());
    return out.str();
  }

 private:
  std::map<const CLI::App*, std::string> summaries_;
};
}  // namespace

}  // namespace fusedet::tools

int main(int argc, char** argv) {
  using namespace fusedet::tools;
  CLI::App app{
      "fusedet - object detection on fused camera + tilting-laser data with boosted cascades\n"
      "trained on a joint feature pool (Klein, Schulz, Frintrop). Each subcommand has its own\n"
      "--help. Data paths default to ../shared/data (the KITTI frames beside the checkout).",
      "fusedet"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string("fusedet ") + FUSEDET_VERSION + "\n" + fusedet::boosting::vectorPathSummary());
  std::string logLevel = "warn";
  app.add_option("--log-level", logLevel, "trace|debug|info|warn|error")->capture_default_str();

  std::vector<Command> sorted = commands();
  std::sort(sorted.begin(), sorted.end(), [](const Command& a, const Command& b) { return a.name < b.name; });
  std::map<CLI::App*, CommandRunner> runners;
  auto list = std::make_shared<CommandListFormatter>();
  for (const Command& c : sorted) {
    CLI::App* sub = app.add_subcommand(c.name, c.description);
    list->summary(sub, c.description);
    runners[sub] = c.setup(*sub);
  }
  app.formatter(list);  // after the subcommands: theirs keep the default formatter
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e);
  }
  // Logs go to stderr so that machine-readable output on stdout (--json, NDJSON) stays clean.
  spdlog::set_default_logger(spdlog::stderr_color_mt("fusedet"));
  spdlog::set_level(spdlog::level::from_str(logLevel));
  for (auto& [sub, run] : runners) {
    if (!sub->parsed()) continue;
    try {
      return run();
    } catch (const std::exception& e) {
      std::cerr << "fusedet " << sub->get_name() << ": error: " << e.what() << "\n";
      return 1;
    }
  }
  return 2;
}
