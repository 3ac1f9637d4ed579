// SPDX-License-Identifier: Apache-2.0
#pragma once
// A KITTI label's 2D box as the object and tracking label files write it: left, top, right,
// bottom in pixels.

#include <optional>

#include "fusedet/core/box.h"

namespace fusedet::fusion {

// The box, or nothing if a corner or the size is not finite or the size is negative. Corners
// near +-1.8e308 are finite while right - left overflows to inf, so the size is checked too.
std::optional<Box> kittiBox(double left, double top, double right, double bottom);

}  // namespace fusedet::fusion
