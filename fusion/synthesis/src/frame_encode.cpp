// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/synthesis/frame_encode.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace fusedet::fusion {

namespace {
std::uint8_t clampByte(double v) { return static_cast<std::uint8_t>(std::clamp(std::lround(v), 0L, 255L)); }
}  // namespace

drivers::CameraFrame encodeYuyvFrame(const cv::Mat& bgr) {
  if (bgr.type() != CV_8UC3 || bgr.cols % 2 != 0) throw std::invalid_argument("encodeYuyvFrame: needs an 8-bit BGR image of even width");
  drivers::CameraFrame f;
  f.width = bgr.cols;
  f.height = bgr.rows;
  f.stride = 2 * bgr.cols;
  f.format = drivers::PixelFormat::kYuyv;
  f.bytes.resize(static_cast<std::size_t>(f.stride) * static_cast<std::size_t>(f.height));
  for (int y = 0; y < bgr.rows; ++y) {
    const cv::Vec3b* row = bgr.ptr<cv::Vec3b>(y);
    std::uint8_t* out = f.bytes.data() + static_cast<std::size_t>(y) * static_cast<std::size_t>(f.stride);
    for (int x = 0; x < bgr.cols; x += 2) {
      double u = 0, v = 0;
      for (int k = 0; k < 2; ++k) {
        const double b = row[x + k][0], g = row[x + k][1], r = row[x + k][2];
        out[2 * (x + k)] = clampByte(16 + 0.2568 * r + 0.5041 * g + 0.0979 * b);
        u += 128 - 0.1482 * r - 0.2910 * g + 0.4392 * b;
        v += 128 + 0.4392 * r - 0.3678 * g - 0.0714 * b;
      }
      out[2 * x + 1] = clampByte(u / 2);
      out[2 * x + 3] = clampByte(v / 2);
    }
  }
  return f;
}

}  // namespace fusedet::fusion
