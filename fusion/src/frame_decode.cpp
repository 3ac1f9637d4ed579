// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/frame_decode.h"

#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <string>

namespace fusedet::fusion {
namespace {
Error frameError(const drivers::CameraFrame& f, std::errc code, const std::string& what) {
  return makeError(code, "camera frame " + std::to_string(f.sequence) + " (" +
                             std::string(drivers::toString(f.format)) + " " + std::to_string(f.width) + "x" +
                             std::to_string(f.height) + "): " + what);
}
}  // namespace

Result<cv::Mat> decodeCameraFrame(const drivers::CameraFrame& f) {
  if (f.width <= 0 || f.height <= 0 || f.width > 16384 || f.height > 16384)
    return frameError(f, std::errc::invalid_argument, "invalid size");
  if (f.format == drivers::PixelFormat::kMjpeg) {
    if (f.bytes.size() < 4 || f.bytes[0] != 0xFF || f.bytes[1] != 0xD8)
      return frameError(f, std::errc::bad_message, "no JPEG start-of-image marker");
    cv::Mat bgr;
    try {
      bgr = cv::imdecode(f.bytes, cv::IMREAD_COLOR);
    } catch (const cv::Exception& e) {
      return frameError(f, std::errc::bad_message, std::string("JPEG decoding failed: ") + e.what());
    }
    if (bgr.empty()) return frameError(f, std::errc::bad_message, "corrupt or truncated JPEG");
    if (bgr.cols != f.width || bgr.rows != f.height)
      return frameError(f, std::errc::bad_message,
                        "JPEG is " + std::to_string(bgr.cols) + "x" + std::to_string(bgr.rows));
    return bgr;
  }
  int bytesPerPixel = 3;
  if (f.format == drivers::PixelFormat::kGray8) bytesPerPixel = 1;
  if (f.format == drivers::PixelFormat::kYuyv) {
    bytesPerPixel = 2;
    if (f.width % 2 != 0) return frameError(f, std::errc::invalid_argument, "YUYV needs an even width");
  }
  const std::size_t row = static_cast<std::size_t>(f.width) * static_cast<std::size_t>(bytesPerPixel);
  const std::size_t stride = f.stride == 0 ? row : static_cast<std::size_t>(f.stride);
  if (f.stride < 0 || stride < row)
    return frameError(f, std::errc::invalid_argument, "stride " + std::to_string(f.stride) + " < row size " + std::to_string(row));
  const std::size_t needed = stride * static_cast<std::size_t>(f.height - 1) + row;
  if (f.bytes.size() < needed)
    return frameError(f, std::errc::bad_message,
                      std::to_string(f.bytes.size()) + " bytes, need " + std::to_string(needed));
  // A view on the frame's bytes; the conversions below write a new image.
  auto* data = const_cast<std::uint8_t*>(f.bytes.data());
  cv::Mat bgr;
  switch (f.format) {
    case drivers::PixelFormat::kBgr24:
      cv::Mat(f.height, f.width, CV_8UC3, data, stride).copyTo(bgr);
      break;
    case drivers::PixelFormat::kGray8:
      cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC1, data, stride), bgr, cv::COLOR_GRAY2BGR);
      break;
    case drivers::PixelFormat::kYuyv:
      cv::cvtColor(cv::Mat(f.height, f.width, CV_8UC2, data, stride), bgr, cv::COLOR_YUV2BGR_YUYV);
      break;
    case drivers::PixelFormat::kMjpeg:
      break;  // handled above
  }
  return bgr;
}

}  // namespace fusedet::fusion
