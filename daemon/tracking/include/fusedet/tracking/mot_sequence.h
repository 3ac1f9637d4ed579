// SPDX-License-Identifier: Apache-2.0
#pragma once
// MotSequence: what the MOT metrics (clear_mot.h, hota.h) score - per frame, the ground-truth
// objects and the tracker's hypotheses, each an id and an image box, after ignored labels and
// regions have been taken out (kitti_tracking_eval.h does that for KITTI). Similarity = box IoU.

#include <cstdint>
#include <vector>

#include "fusedet/core/box.h"

namespace fusedet::tracking {

struct MotObject {
  std::int64_t id = 0;  // unique within its side (truth or hypotheses) of the sequence
  Box box;
};

struct MotFrame {
  std::vector<MotObject> truth;
  std::vector<MotObject> hypotheses;
};

using MotSequence = std::vector<MotFrame>;

}  // namespace fusedet::tracking
