// SPDX-License-Identifier: Apache-2.0
#pragma once
// BGR image -> CameraFrame in a camera's raw format: what a V4L2 camera would have delivered for
// that picture (synthetic logs). YUYV uses ITU-R BT.601 limited range, the inverse of what
// decodeCameraFrame (OpenCV COLOR_YUV2BGR_YUYV) applies; chroma is averaged over pixel pairs.

#include <opencv2/core/mat.hpp>

#include "fusedet/drivers/messages.h"

namespace fusedet::fusion {

// bgr: CV_8UC3 of even width (std::invalid_argument otherwise). Stamp and sequence are the caller's.
drivers::CameraFrame encodeYuyvFrame(const cv::Mat& bgr);

}  // namespace fusedet::fusion
