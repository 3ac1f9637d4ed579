// SPDX-License-Identifier: Apache-2.0
#pragma once
// outcomes.json: the per-frame outcomes of one `fusedet experiments` run - for every class,
// protocol (leave-one-drive-out or k drive-disjoint folds) and configuration, each test frame's
// name, its positives and its counted detections (score, hit or false alarm) - everything F and AP
// are computed from (precision_recall.h), and the matching rule that produced them. Two runs'
// files compare frame by frame (paired_comparison.h, `fusedet compare`). Only numbers and frame
// names: no pixels, no labels. Format: docs/outcomes-format.md.

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

#include "fusedet/boost/evaluation.h"
#include "fusedet/boost/precision_recall.h"

namespace fusedet::boosting {

// One (class, protocol, configuration) of a run: its test frames in pooled order.
struct OutcomeSet {
  std::string className;
  std::string protocol;  // protocolName(): "lodo", "3fold", ...
  std::size_t folds = 0;
  std::string config;       // "all", "laser", "and", "hog", ...
  MatchConfig rule;         // how detections were matched to labels (className = the class)
  std::vector<std::string> frameIds;  // parallel to frames; unique
  std::vector<FrameOutcome> frames;
};

struct RunOutcomes {
  std::string command;  // the command line that made the run
  std::vector<OutcomeSet> sets;
};

// "lodo" when every group (drive) is a fold of its own, else "<folds>fold" (e.g. "3fold").
std::string protocolName(std::size_t folds, std::size_t groups);

// A file that is not a valid outcomes file: what() = "<source>: <problem>".
struct OutcomesError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

// Text of the file (format "fusedet-outcomes", version 1): one line per frame, scores as the
// shortest decimal that reads back to the same double. Throws std::invalid_argument for an
// inconsistent set (ids and frames of different lengths).
std::string outcomesToText(const RunOutcomes& run);
// Parses and checks everything (format, version, types, finite scores >= 0... see the .cpp);
// throws OutcomesError naming `source` and the field.
RunOutcomes outcomesFromText(const std::string& text, const std::string& source);

void writeOutcomes(const std::filesystem::path& file, const RunOutcomes& run);
// `path` = the file, or a run's output directory holding outcomes.json.
RunOutcomes readOutcomes(const std::filesystem::path& path);

}  // namespace fusedet::boosting
