// SPDX-License-Identifier: Apache-2.0
#pragma once
// The `fusedet` command line: one file per subcommand (cmd_<name>.cpp), each registering itself
// here at start-up, so adding a command touches no shared file.

#include <CLI/CLI.hpp>
#include <functional>
#include <string>
#include <vector>

namespace fusedet::tools {

// A subcommand's setup adds its options to `app` and returns the function that runs it
// (exit code). Exceptions thrown by the runner are reported by main() as "fusedet NAME: error: ...".
using CommandRunner = std::function<int()>;
using CommandSetup = std::function<CommandRunner(CLI::App& app)>;

struct Command {
  std::string name;
  std::string description;  // one line: `fusedet --help` lists it; the long text goes in the setup's app.description()
  CommandSetup setup;
};

bool registerCommand(std::string name, std::string description, CommandSetup setup);
const std::vector<Command>& commands();

}  // namespace fusedet::tools
