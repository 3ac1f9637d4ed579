// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/clear_mot.h"

#include <Eigen/Core>
#include <limits>
#include <map>
#include <optional>

#include "fusedet/tracking/assignment.h"

namespace fusedet::tracking {

double ClearMot::mota() const {
  return truth ? 1.0 - static_cast<double>(misses + falsePositives + idSwitches) / static_cast<double>(truth) : 0.0;
}

double ClearMot::motp() const { return matches ? iouSum / static_cast<double>(matches) : 0.0; }

ClearMot clearMot(const MotSequence& sequence, double minIou, ClearMotTimeline* timeline) {
  struct TruthHistory {
    std::size_t frames = 0, matched = 0, segments = 0;
    std::optional<std::int64_t> lastHypothesis;   // matched in any earlier frame
    std::optional<std::int64_t> previousFrame;    // matched in the previous frame
  };
  std::map<std::int64_t, TruthHistory> history;
  ClearMot r;
  constexpr double kForbidden = std::numeric_limits<double>::infinity();
  for (const MotFrame& f : sequence) {
    r.truth += f.truth.size();
    r.hypotheses += f.hypotheses.size();
    const auto nt = static_cast<Eigen::Index>(f.truth.size()), nh = static_cast<Eigen::Index>(f.hypotheses.size());
    Eigen::MatrixXd cost(nt, nh);
    Eigen::MatrixXd sim(nt, nh);
    for (Eigen::Index i = 0; i < nt; ++i) {
      const TruthHistory& h = history[f.truth[static_cast<std::size_t>(i)].id];
      for (Eigen::Index j = 0; j < nh; ++j) {
        const MotObject& hyp = f.hypotheses[static_cast<std::size_t>(j)];
        sim(i, j) = iou(f.truth[static_cast<std::size_t>(i)].box, hyp.box);
        const bool continues = h.previousFrame && *h.previousFrame == hyp.id;
        cost(i, j) = sim(i, j) >= minIou ? -(sim(i, j) + (continues ? 1000.0 : 0.0)) : kForbidden;
      }
    }
    const std::vector<int> match = assign(cost, 0.0);
    std::size_t matched = 0;
    std::vector<TruthEvent> events;
    for (Eigen::Index i = 0; i < nt; ++i) {
      TruthHistory& h = history[f.truth[static_cast<std::size_t>(i)].id];
      ++h.frames;
      TruthEvent& e = events.emplace_back();
      e.truth = f.truth[static_cast<std::size_t>(i)].id;
      const int j = match[static_cast<std::size_t>(i)];
      if (j < 0) {
        h.previousFrame.reset();
        continue;
      }
      const std::int64_t hypId = f.hypotheses[static_cast<std::size_t>(j)].id;
      e.hypothesis = hypId;
      ++matched;
      ++h.matched;
      r.iouSum += sim(i, j);
      e.idSwitch = h.lastHypothesis && *h.lastHypothesis != hypId;
      if (e.idSwitch) ++r.idSwitches;
      e.resumed = !h.previousFrame && h.segments > 0;
      if (!h.previousFrame) ++h.segments;
      h.lastHypothesis = hypId;
      h.previousFrame = hypId;
    }
    // A truth absent from this frame is not tracked in it either.
    for (auto& [id, h] : history) {
      bool present = false;
      for (const MotObject& t : f.truth) present = present || t.id == id;
      if (!present) h.previousFrame.reset();
    }
    if (timeline) timeline->push_back(std::move(events));
    r.matches += matched;
    r.misses += f.truth.size() - matched;
    r.falsePositives += f.hypotheses.size() - matched;
  }
  for (const auto& [id, h] : history) {
    if (h.frames == 0) continue;
    ++r.trajectories;
    if (h.segments > 1) r.fragmentations += h.segments - 1;
    const double ratio = static_cast<double>(h.matched) / static_cast<double>(h.frames);
    if (ratio > 0.8) ++r.mostlyTracked;
    else if (ratio >= 0.2) ++r.partiallyTracked;
    else ++r.mostlyLost;
  }
  return r;
}

}  // namespace fusedet::tracking
