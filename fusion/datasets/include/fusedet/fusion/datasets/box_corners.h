// SPDX-License-Identifier: Apache-2.0
#pragma once
// A 2D box as label files write it by its corners: left, top, right, bottom in pixels (KITTI
// object and tracking labels, CVAT's xtl/ytl/xbr/ybr).

#include <optional>

#include "fusedet/core/box.h"

namespace fusedet::fusion {

// The box, or nothing if a corner or the size is not finite or the size is negative. Corners
// near +-1.8e308 are finite while right - left overflows to inf, so the size is checked too.
std::optional<Box> boxFromCorners(double left, double top, double right, double bottom);

}  // namespace fusedet::fusion
