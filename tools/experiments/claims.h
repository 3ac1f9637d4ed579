// SPDX-License-Identifier: Apache-2.0
#pragma once
// Measures with bootstrap intervals, the paper's claims judged by paired comparison, the goals.

#include <map>
#include <string>
#include <vector>

#include "fusedet/boost/bootstrap.h"
#include "report.h"

namespace fusedet::tools::experiments {

// Measures of pooled frames with their bootstrap intervals.
struct Measured {
  Estimate f, ap;
};

Measured measure(const std::vector<boosting::FrameOutcome>& frames, const boosting::BootstrapConfig& b);

// Paired difference a - b of F and AP on the same resampled frames (fusedet/boost/paired_comparison.h).
Claim compare(const std::string& cls, const std::string& key, const std::string& text, const std::string& lhs,
              const std::vector<boosting::FrameOutcome>& a, const std::string& rhs,
              const std::vector<boosting::FrameOutcome>& b, const boosting::BootstrapConfig& boot);

// The paper's claims for one class (joint pool > laser only, > camera only, > AND; corners help; > HOG for
// person), each judged on the paired interval of the configurations' outcomes where both ran.
void judgeClaims(ExperimentReport& report, const std::string& cls,
                 std::map<std::string, std::vector<boosting::FrameOutcome>>& fr, const boosting::BootstrapConfig& boot);

// The goals of the brief (F per class, person against HOG) against the `all` rows.
void setGoals(ExperimentReport& report);

}  // namespace fusedet::tools::experiments
