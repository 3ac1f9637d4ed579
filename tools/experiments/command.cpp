// SPDX-License-Identifier: Apache-2.0
// fusedet experiments: registers the command (options.h defines its options, run.h runs it).

#include <memory>
#include <string>

#include "../command.h"
#include "options.h"
#include "run.h"

namespace fusedet::tools {
namespace {
using namespace experiments;

const bool registered = registerCommand(
    "experiments",
    "Reproduce the paper's experiments (Tab. 2-7, Fig. 7) with cross-drive validation: F, AP, intervals, claims",
    [](CLI::App& app) {
      auto o = std::make_shared<ExperimentOptions>();
      addExperimentOptions(app, o);
      return [o, &app] {
        std::string cmd = "fusedet experiments";
        for (const auto* opt : app.get_options()) {
          if (opt->count() == 0 || opt->get_name() == "--help") continue;
          cmd += " " + opt->get_name();
          if (opt->get_expected_max() == 0) continue;  // a flag
          for (const auto& r : opt->results()) cmd += " " + r;
        }
        o->commandLine = cmd;
        o->minNeighborsGiven = app.count("--min-neighbors") > 0;
        o->laserExtentGiven = app.count("--laser-extent") > 0;
        return runExperiments(*o);
      };
    });

}  // namespace
}  // namespace fusedet::tools
