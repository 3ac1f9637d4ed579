// SPDX-License-Identifier: Apache-2.0
#include "fusedet/daemon/live/view_images.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "fusedet/fusion/camera_layers.h"

namespace fusedet::daemon::live {
namespace {

std::vector<std::uint8_t> jpeg(const cv::Mat& image) {
  std::vector<std::uint8_t> out;
  cv::imencode(".jpg", image, out, {cv::IMWRITE_JPEG_QUALITY, kJpegQuality});
  return out;
}

}  // namespace

std::optional<std::vector<std::uint8_t>> colourJpeg(const LayerStack& stack) {
  if (!fusion::hasCameraImage(stack)) return std::nullopt;
  return jpeg(fusion::cameraImage(stack));
}

std::vector<std::uint8_t> layerJpeg(const Layer& l) {
  if (l.data.type() == CV_8U) return jpeg(l.data);
  cv::Mat values;
  l.data.convertTo(values, CV_32F);
  cv::Mat valid = l.hasMask() ? l.valid.clone() : cv::Mat(values.size(), CV_8U, cv::Scalar(255));
  valid &= (values == values);  // NaN is no value
  double lo = 0, hi = 0;
  cv::minMaxLoc(values, &lo, &hi, nullptr, nullptr, valid);
  cv::Mat grey;
  values.convertTo(grey, CV_8U, hi > lo ? 255.0 / (hi - lo) : 0.0, hi > lo ? -lo * 255.0 / (hi - lo) : 0.0);
  cv::Mat colour;
  cv::applyColorMap(grey, colour, cv::COLORMAP_TURBO);
  colour.setTo(cv::Scalar(0, 0, 0), valid == 0);
  return jpeg(colour);
}

}  // namespace fusedet::daemon::live
