// SPDX-License-Identifier: Apache-2.0
#pragma once
// Which physical object each label of a KITTI tracking drive is. The drives 0005 and 0009 of
// ../shared/data carry their tracking label file (tracking_label_02_NNNN.txt: the object-layout
// line of label_2/ preceded by frame and track id), so the same car or cyclist seen in many
// frames can be counted once (a learning curve's "distinct objects", boost/learning_curve.h).

#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "fusedet/core/label.h"

namespace fusedet::fusion {

struct KittiTrackedBox {
  int trackId = -1;  // -1: DontCare
  std::string type;  // KITTI class, e.g. "Cyclist"
  Box box;
};

struct KittiTracks {
  std::map<int, std::vector<KittiTrackedBox>> frames;  // frame number -> its boxes

  // Track id of a label of frame `frame`: the tracked box of the same KITTI class whose corners
  // lie within 0.01 px of the label's; -1 when there is none (or only DontCare).
  int trackOf(int frame, const Label& label) const;
  // Per label of that frame: "<drive>/track <id>", or "" when it has no track (see trackOf).
  std::vector<std::string> objectIds(const std::string& drive, int frame, const Labels& labels) const;
};

// Parses the text of a tracking label file. Blank lines are skipped; a line without frame, track
// id, class, truncation, occlusion, alpha and four box numbers, or with a negative box, throws
// std::runtime_error naming `source` and the line.
KittiTracks parseKittiTracks(const std::string& text, const std::string& source = "tracking labels");
// The tracking_label_02_*.txt of a KITTI directory; empty when there is none; throws
// std::runtime_error when there are several or one is malformed.
KittiTracks readKittiTracks(const std::filesystem::path& root);

}  // namespace fusedet::fusion
