// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/box_corners.h"

#include <cmath>

namespace fusedet::fusion {

std::optional<Box> boxFromCorners(double left, double top, double right, double bottom) {
  const Box box{left, top, right - left, bottom - top};
  if (!std::isfinite(box.x) || !std::isfinite(box.y) || !std::isfinite(box.w) || !std::isfinite(box.h) ||
      !(box.w >= 0) || !(box.h >= 0))
    return std::nullopt;
  return box;
}

}  // namespace fusedet::fusion
