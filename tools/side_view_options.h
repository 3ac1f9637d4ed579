#pragma once
// The side-view cascade's options (boosting::TrainingConfig::SideView, boost/cascade_trainer.h),
// one definition for `fusedet train` and `fusedet experiments`.

#include <CLI/CLI.hpp>

#include "fusedet/boost/cascade_trainer.h"

namespace fusedet::tools {

inline void addSideViewOptions(CLI::App& app, boosting::TrainingConfig::SideView& s) {
  app.add_option("--side-view", s.minAspect,
                 "W > 0: after each cascade, train a second one of the class for wide (side-view) objects: "
                 "positives only the labels with w/h >= W (mirrored as usual), window --side-view-aspect at the "
                 "same height, negatives as usual (narrower objects of the class are no negatives); the model "
                 "holds both (\"aspect_cascades\", format version 4) and detection scans each at its own aspect "
                 "and merges their detections (boost/aspect_cascades.h). No such positives: the first cascade "
                 "alone. The first cascade is trained (and cached) as without it. Not with a validation part. "
                 "0 = off (default)")
      ->check(CLI::Range(0.0, 100.0))
      ->capture_default_str();
  app.add_option("--side-view-aspect", s.windowAspect, "with --side-view: the side-view window's w/h")
      ->check(CLI::Range(0.5, 10.0))
      ->capture_default_str();
  app.add_option("--side-view-max-fa", s.stageMaxFalseAlarm,
                 "with --side-view: its largest false-alarm rate per stage (0 = the first cascade's, --max-fa)")
      ->check(CLI::Range(0.0, 0.99))
      ->capture_default_str();
  app.add_option("--side-view-jitter", s.jitterCopies,
                 "with --side-view: jittered copies per side-view positive (0 = the first cascade's, --jitter)")
      ->check(CLI::Range(0, 100))
      ->capture_default_str();
}

}  // namespace fusedet::tools
