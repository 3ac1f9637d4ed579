// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/undistorter.h"

#include <opencv2/calib3d.hpp>
#include <opencv2/core/eigen.hpp>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::fusion {

Undistorter::Undistorter(const CameraModel& model) : size_(model.width, model.height) {
  if (!model.hasDistortion()) return;
  cv::Mat K;
  cv::eigen2cv(model.K, K);
  // New camera matrix = K: the undistorted image is the pinhole K of the model, so projection
  // needs no second matrix.
  cv::initUndistortRectifyMap(K, cv::Mat(model.distortion), cv::Mat(), K, size_, CV_16SC2, map1_, map2_);
}

cv::Mat Undistorter::undistort(const cv::Mat& image) const {
  if (image.size() != size_)
    throw std::invalid_argument("Undistorter: image is " + std::to_string(image.cols) + "x" +
                                std::to_string(image.rows) + ", camera model is " + std::to_string(size_.width) +
                                "x" + std::to_string(size_.height));
  if (identity()) return image;
  cv::Mat out;
  cv::remap(image, out, map1_, map2_, cv::INTER_LINEAR, cv::BORDER_CONSTANT);
  return out;
}

}  // namespace fusedet::fusion
