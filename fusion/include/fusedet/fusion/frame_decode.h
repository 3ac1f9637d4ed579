// SPDX-License-Identifier: Apache-2.0
#pragma once
// CameraFrame (raw bytes as the V4L2 driver captured them) -> 8-bit BGR image.

#include <opencv2/core/mat.hpp>

#include "fusedet/core/result.h"
#include "fusedet/drivers/messages.h"

namespace fusedet::fusion {

// BGR24, GRAY8, YUYV (4:2:2, Y0 U Y1 V) and MJPEG. Errors (std::errc::invalid_argument or
// bad_message) name the frame's sequence number and the problem: size or stride inconsistent
// with the bytes, odd YUYV width, undecodable JPEG, JPEG of another size than the frame says.
Result<cv::Mat> decodeCameraFrame(const drivers::CameraFrame& frame);

}  // namespace fusedet::fusion
