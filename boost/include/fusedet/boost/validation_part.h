#pragma once
// The trainer's validation part (cascade_trainer.h, TrainingConfig::validation): about 1/n of the
// training items are held back - not trained on (neither positives nor negatives) - and
//  - each stage's threshold is placed so that the stage keeps min_hit of the held-back positives
//    that reach it (the training positives' stage sums are optimistic: the stumps were fitted on
//    them, so their weakest one says little about an unseen object), and
//  - the stage count (and so the false-alarm rate reached) is the one with the best F on the
//    held-back frames (ties: better AP, then more stages).
//
// Which items: drive-disjoint when the items come from two or more groups (DatasetItem::group is
// the drive): whole groups, smallest first (then by name), until they hold >= 1/n of the items,
// never every group. From one group: frame-disjoint, every n-th item (n-1, 2n-1, ...).

#include <cstddef>
#include <optional>
#include <vector>

#include "fusedet/boost/chain_evaluation.h"
#include "fusedet/boost/evaluation.h"
#include "fusedet/core/dataset.h"

namespace fusedet::boosting {

struct ValidationConfig {
  int part = 0;  // 0 = off; n >= 2: hold back about 1/n of the training items
  // Detection on the held-back frames (as at test time) and its scoring. An empty
  // match.className means matchConfigFor(class) with the trainer's positive height / occlusion.
  DetectionSetup detection;
  MatchConfig match;
  // Share of the held-back positives reaching a stage that it keeps; 0 = stage thresholds from the
  // training positives (the part then only chooses the stage count). Lower than the training
  // min_hit: unseen positives have a long tail of weak sums, and keeping 0.995 of them (their
  // weakest, in practice) made every stage run to its round limit at high false-alarm rates
  // (issue 15 notes: 3-fold car, 2 hits / 2059 false alarms in the first fold).
  double minHit = 0.98;
  // A held-back positive threshold needs at least this many held-back positives reaching the stage
  // (else the training positives' threshold stays).
  std::size_t minPositives = 5;
  // Stage counts whose cascade still accepts more than this share of the label-free training
  // windows are not tried (their raw hits would swamp grouping; they are never the best).
  double maxCascadeFalseAlarm = 1e-3;
};

// Indices of `items` held back for validation (rule above), ascending. Empty when part == 0 or
// when the rule holds back nothing (fewer than `part` items of one group).
std::vector<std::size_t> validationItems(const std::vector<DatasetItem>& items, int part);

// F and AP of the cascade truncated to `stages` stages on the held-back frames.
struct StageCountScore {
  std::size_t stages = 0;
  std::optional<double> f, ap;
  std::size_t hits = 0, falseAlarms = 0, misses = 0;
};

// The stage count to keep: the best F (undefined counts as below 0), ties by AP, then by more
// stages. nullopt when `scores` is empty or no F is defined and positive (keep every stage).
std::optional<std::size_t> chooseStageCount(const std::vector<StageCountScore>& scores);

}  // namespace fusedet::boosting
