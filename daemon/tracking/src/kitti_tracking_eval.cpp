// SPDX-License-Identifier: Apache-2.0
#include "fusedet/tracking/kitti_tracking_eval.h"

#include <algorithm>
#include <stdexcept>

#include "fusedet/boost/class_rules.h"

namespace fusedet::tracking {

ClassTracking evaluateTracking(const std::vector<TrackedFrame>& frames, const std::string& className) {
  const boosting::MatchConfig config = boosting::matchConfigFor(className, boosting::VanPolicy::kIgnore, kKittiTrackingMinIou);
  ClassTracking out;
  out.className = className;
  out.frames = frames.size();
  MotSequence sequence;
  sequence.reserve(frames.size());
  std::int64_t untrackedLabelId = -1;  // a positive label without a KITTI track id: an id of its own
  for (const TrackedFrame& f : frames) {
    if (f.labelTracks.size() != f.labels.size())
      throw std::invalid_argument("evaluateTracking: one track id per label expected");
    std::vector<Detection> all, ofConfirmed;
    std::vector<const TrackedDetection*> confirmedSource;
    for (const TrackedDetection& d : f.detections) {
      if (d.className != className) continue;
      Detection det;
      det.className = d.className;
      det.box = d.box;
      det.score = d.score;
      all.push_back(det);
      if (d.track && d.confirmed) {
        ofConfirmed.push_back(det);
        confirmedSource.push_back(&d);
      }
    }
    const boosting::StackMatch rawMatch = boosting::matchDetections(all, f.labels, config);
    const boosting::StackMatch trackMatch = boosting::matchDetections(ofConfirmed, f.labels, config);
    out.raw.add(rawMatch);
    out.confirmed.add(trackMatch);
    MotFrame m;
    for (std::size_t i = 0; i < f.labels.size(); ++i)
      if (trackMatch.labelRoles[i] == boosting::LabelRole::kPositive)
        m.truth.push_back(MotObject{f.labelTracks[i] >= 0 ? f.labelTracks[i] : untrackedLabelId--, f.labels[i].box});
    for (std::size_t j = 0; j < ofConfirmed.size(); ++j)
      if (trackMatch.detections[j] != boosting::DetectionOutcome::kIgnored)
        m.hypotheses.push_back(MotObject{static_cast<std::int64_t>(*confirmedSource[j]->track), ofConfirmed[j].box});
    sequence.push_back(std::move(m));
  }
  out.clear = clearMot(sequence, kKittiTrackingMinIou, &out.timeline);
  out.hota = hota(sequence);
  return out;
}

int strokeOfSweep(const std::vector<std::int64_t>& strokeStartsNs, std::int64_t sweepStartNs, std::int64_t sweepEndNs) {
  const std::int64_t middle = sweepStartNs + (sweepEndNs - sweepStartNs) / 2;
  const auto after = std::upper_bound(strokeStartsNs.begin(), strokeStartsNs.end(), middle);
  return static_cast<int>(after - strokeStartsNs.begin()) - 1;
}

}  // namespace fusedet::tracking
