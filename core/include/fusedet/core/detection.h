// SPDX-License-Identifier: Apache-2.0
#pragma once
// Detection: one object found in one LayerStack, as the detector reports it and the daemon sends it.

#include <array>
#include <cstdint>
#include <optional>
#include <string>

#include "fusedet/core/box.h"
#include "fusedet/core/stamp.h"

namespace fusedet {

struct Detection {
  std::string className;  // "car", "person", "bike", "socket", or an imported model's name
  double score = 0;       // larger = more confident; cascade sum of the last stage or group size
  Box box;                // reference (camera) pixels
  Box unitBox;            // the same box in unit-square coordinates of the stack
  // Position in the robot frame [m], from the distance layer inside the box, when it has one.
  std::optional<std::array<double, 3>> position;
  Stamp stamp;                 // stamp of the stack
  std::uint64_t stackId = 0;   // LayerStack::id
};

}  // namespace fusedet
