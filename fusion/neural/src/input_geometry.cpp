// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/neural/input_geometry.h"

#include <algorithm>
#include <cmath>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::fusion {
namespace {
void checkSizes(cv::Size image, cv::Size input) {
  if (image.width <= 0 || image.height <= 0 || input.width <= 0 || input.height <= 0)
    throw std::invalid_argument("network input geometry: empty image (" + std::to_string(image.width) + "x" +
                                std::to_string(image.height) + ") or input (" + std::to_string(input.width) + "x" +
                                std::to_string(input.height) + ")");
}
}  // namespace

Box InputGeometry::toImage(const Box& b) const {
  return Box{(b.x - padX) / scaleX, (b.y - padY) / scaleY, b.w / scaleX, b.h / scaleY};
}

InputGeometry letterboxGeometry(cv::Size image, cv::Size input) {
  checkSizes(image, input);
  InputGeometry g;
  g.image = image;
  g.input = input;
  const double r = std::min(double(input.width) / image.width, double(input.height) / image.height);
  g.scaleX = g.scaleY = r;
  const int w = static_cast<int>(std::lround(image.width * r)), h = static_cast<int>(std::lround(image.height * r));
  g.padX = (input.width - w) / 2;
  g.padY = (input.height - h) / 2;
  return g;
}

InputGeometry resizeGeometry(cv::Size image, cv::Size input) {
  checkSizes(image, input);
  InputGeometry g;
  g.image = image;
  g.input = input;
  g.scaleX = double(input.width) / image.width;
  g.scaleY = double(input.height) / image.height;
  return g;
}

cv::Mat makeInputImage(const cv::Mat& bgr, const InputGeometry& g) {
  if (bgr.type() != CV_8UC3 || bgr.size() != g.image)
    throw std::invalid_argument("network input: expected an 8-bit BGR image of " + std::to_string(g.image.width) +
                                "x" + std::to_string(g.image.height));
  const cv::Size scaled(static_cast<int>(std::lround(g.image.width * g.scaleX)),
                        static_cast<int>(std::lround(g.image.height * g.scaleY)));
  cv::Mat resized;
  cv::resize(bgr, resized, scaled, 0, 0, cv::INTER_LINEAR);
  if (scaled == g.input) return resized;
  cv::Mat input(g.input, CV_8UC3, cv::Scalar(114, 114, 114));
  resized.copyTo(input(cv::Rect(g.padX, g.padY, scaled.width, scaled.height)));
  return input;
}

}  // namespace fusedet::fusion
