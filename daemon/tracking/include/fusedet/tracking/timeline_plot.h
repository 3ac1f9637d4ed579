// SPDX-License-Identifier: Apache-2.0
#pragma once
// A picture of tracks over time (docs/tracking.md): per class a panel with one row per ground-truth
// object and one column per frame; a cell is filled in the colour of the track id that matched
// the object there (its number written where it starts), outlined grey when the object was
// missed; a red bar marks an id switch, an orange triangle a fragmentation (matched again after
// an interruption). Drawn from ClearMot's timeline only: numbers, no camera images.

#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/tracking/clear_mot.h"

namespace fusedet::tracking {

struct TimelinePanel {
  std::string title;  // e.g. "car: MOTA 0.41, 2 id switches, 3 fragmentations"
  ClearMotTimeline timeline;
};

// BGR image, panels stacked top to bottom; `caption` on top.
cv::Mat drawTimeline(const std::vector<TimelinePanel>& panels, const std::string& caption);

}  // namespace fusedet::tracking
