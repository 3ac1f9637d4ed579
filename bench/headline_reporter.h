// SPDX-License-Identifier: Apache-2.0
#pragma once
// HeadlineReporter: Google Benchmark's console output, plus each benchmark's adjusted time kept by
// name so main() can print the "bench: <key> <value>" headline lines (in the run's time unit).

#include <benchmark/benchmark.h>

#include <map>
#include <string>
#include <vector>

namespace fusedet::bench {

class HeadlineReporter : public benchmark::ConsoleReporter {
 public:
  void ReportRuns(const std::vector<Run>& runs) override {
    ConsoleReporter::ReportRuns(runs);
    for (const Run& r : runs)
      if (r.run_type == Run::RT_Iteration) {
        wall[r.benchmark_name()] = r.GetAdjustedRealTime();
        cpu[r.benchmark_name()] = r.GetAdjustedCPUTime();
      }
  }
  std::map<std::string, double> wall;  // real time per iteration
  std::map<std::string, double> cpu;   // CPU time per iteration
};

}  // namespace fusedet::bench
