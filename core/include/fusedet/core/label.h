// SPDX-License-Identifier: Apache-2.0
#pragma once
// Label: a ground-truth box of a data set stack. Ignore regions (KITTI DontCare, classes
// configured as "ignore") are labels with `ignore` set: matching them is neither a hit nor a
// false alarm.

#include <string>
#include <vector>

#include "fusedet/core/box.h"

namespace fusedet {

struct Label {
  std::string className;  // project class ("car", "person", "bike") or source class if unmapped
  std::string sourceClass;  // as in the source data set ("Car", "Van", "DontCare", ...)
  Box box;                  // reference pixels
  double truncation = 0;    // KITTI object: fraction [0,1]; KITTI tracking: level 0, 1, 2
  int occlusion = 0;        // 0 fully visible .. 3 unknown (KITTI)
  bool ignore = false;      // ignore region
  std::string origin = "human";  // who drew it: "human" or "teacher" (a network: fusedet autolabel)
};

using Labels = std::vector<Label>;

}  // namespace fusedet
