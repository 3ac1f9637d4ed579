// SPDX-License-Identifier: Apache-2.0
#pragma once
// One `fusedet experiments` run: folds, configurations, sweep, learning curves, models; writes the
// report after every step.

#include "options.h"

namespace fusedet::tools::experiments {

int runExperiments(ExperimentOptions o);

}  // namespace fusedet::tools::experiments
