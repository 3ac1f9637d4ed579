// SPDX-License-Identifier: Apache-2.0
#pragma once
// Undistortion of camera images with remap tables computed once per camera model (paper §3.1:
// barrel distortion correction). The undistorted image keeps the model's K, so laser points
// project into it with the plain pinhole K.

#include <opencv2/core/mat.hpp>

#include "fusedet/fusion/camera_model.h"

namespace fusedet::fusion {

class Undistorter {
 public:
  explicit Undistorter(const CameraModel& model);

  // BGR (or grey) image of the model's size -> undistorted image of the same size; a model
  // without distortion returns the input unchanged (no copy). Throws std::invalid_argument on a
  // size mismatch.
  cv::Mat undistort(const cv::Mat& image) const;
  bool identity() const { return map1_.empty(); }

 private:
  cv::Size size_;
  cv::Mat map1_, map2_;  // fixed-point tables (CV_16SC2 + CV_16UC1): fastest for cv::remap
};

}  // namespace fusedet::fusion
