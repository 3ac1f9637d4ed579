// SPDX-License-Identifier: Apache-2.0
#pragma once
// Camera-only peers for the person class, run on the same test frames as our cascades:
// OpenCV's HOG people detector (Dalal-Triggs SVM, HOGDescriptor::getDefaultPeopleDetector) and
// the Haar full-body cascade shipped by opencv-data (haarcascade_fullbody.xml).

#include <filesystem>
#include <memory>
#include <opencv2/core/mat.hpp>
#include <string>
#include <vector>

#include "fusedet/core/detection.h"
#include "fusedet/core/layer_stack.h"

namespace fusedet::tools::experiments {

// The camera image of a stack (fusion::cameraImage) at the stack's reference size, where the peers'
// boxes are scored. Throws naming the missing layer when the stack has no colour layers.
cv::Mat stackToBgr(const LayerStack& stack);

class PersonPeer {
 public:
  virtual ~PersonPeer() = default;
  virtual std::string name() const = 0;         // "hog", "haar_fullbody"
  virtual std::string description() const = 0;  // for the report
  // Detections in the image's pixels, class "person".
  virtual std::vector<Detection> detect(const cv::Mat& bgr) const = 0;
};

// The image is enlarged by `upscale` first: the HOG window is 64x128 and most KITTI pedestrians
// are smaller. HOG boxes are shrunk to the person inside the window as OpenCV's own people
// detection sample does (10% off each side, 7% off the top, 80% of the height).
std::unique_ptr<PersonPeer> makeHogPeer(double upscale = 2.0);
// Throws if the cascade file cannot be loaded.
std::unique_ptr<PersonPeer> makeHaarFullbodyPeer(const std::filesystem::path& cascadeFile,
                                                 double upscale = 2.0);

// Where opencv-data installs the Haar cascades.
std::filesystem::path defaultHaarFullbodyPath();

}  // namespace fusedet::tools::experiments
