// SPDX-License-Identifier: Apache-2.0
#include "peers.h"

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>
#include <stdexcept>

#include "fusedet/fusion/camera_layers.h"

namespace fusedet::tools::experiments {
namespace {

Detection personBox(const cv::Rect& r, double score, double upscale) {
  Detection d;
  d.className = "person";
  d.score = score;
  d.box = Box{r.x / upscale, r.y / upscale, r.width / upscale, r.height / upscale};
  return d;
}

class HogPeer final : public PersonPeer {
 public:
  explicit HogPeer(double upscale) : upscale_(upscale) {
    hog_.setSVMDetector(cv::HOGDescriptor::getDefaultPeopleDetector());
  }
  std::string name() const override { return "hog"; }
  std::string description() const override {
    return "OpenCV HOG people detector (getDefaultPeopleDetector), image x" + fmt(upscale_) +
           ", stride 8, scale 1.05, grouping 2";
  }
  std::vector<Detection> detect(const cv::Mat& bgr) const override {
    cv::Mat img;
    cv::resize(bgr, img, {}, upscale_, upscale_, cv::INTER_LINEAR);
    std::vector<cv::Rect> found;
    std::vector<double> weights;
    hog_.detectMultiScale(img, found, weights, 0, cv::Size(8, 8), cv::Size(0, 0), 1.05, 2);
    std::vector<Detection> out;
    for (std::size_t i = 0; i < found.size(); ++i) {
      cv::Rect r = found[i];
      // The person fills the middle of the 64x128 window (OpenCV's peopledetect sample).
      r.x += cvRound(r.width * 0.1);
      r.width = cvRound(r.width * 0.8);
      r.y += cvRound(r.height * 0.07);
      r.height = cvRound(r.height * 0.8);
      out.push_back(personBox(r, i < weights.size() ? weights[i] : 0.0, upscale_));
    }
    return out;
  }

 private:
  static std::string fmt(double v) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%g", v);
    return buf;
  }
  cv::HOGDescriptor hog_;
  double upscale_;
};

class HaarPeer final : public PersonPeer {
 public:
  HaarPeer(const std::filesystem::path& file, double upscale) : file_(file), upscale_(upscale) {
    if (!cascade_.load(file.string()))
      throw std::runtime_error(file.string() + ": cannot load Haar cascade (is opencv-data installed?)");
  }
  std::string name() const override { return "haar_fullbody"; }
  std::string description() const override {
    char buf[64];
    std::snprintf(buf, sizeof buf, "%g", upscale_);
    return "OpenCV CascadeClassifier with " + file_.filename().string() + ", image x" + buf +
           ", scale 1.1, minNeighbors 3";
  }
  std::vector<Detection> detect(const cv::Mat& bgr) const override {
    cv::Mat gray, img;
    cv::cvtColor(bgr, gray, cv::COLOR_BGR2GRAY);
    cv::resize(gray, img, {}, upscale_, upscale_, cv::INTER_LINEAR);
    std::vector<cv::Rect> found;
    std::vector<int> neighbours;  // windows grouped into each box: the score
    cascade_.detectMultiScale(img, found, neighbours, 1.1, 3);
    std::vector<Detection> out;
    for (std::size_t i = 0; i < found.size(); ++i)
      out.push_back(personBox(found[i], i < neighbours.size() ? neighbours[i] : 0.0, upscale_));
    return out;
  }

 private:
  std::filesystem::path file_;
  double upscale_;
  mutable cv::CascadeClassifier cascade_;  // detectMultiScale is not const in OpenCV 4.6
};

}  // namespace

cv::Mat stackToBgr(const LayerStack& stack) {
  cv::Mat bgr = fusion::cameraImage(stack);
  if (bgr.cols != stack.width() || bgr.rows != stack.height())
    cv::resize(bgr, bgr, cv::Size(stack.width(), stack.height()));
  return bgr;
}

std::unique_ptr<PersonPeer> makeHogPeer(double upscale) { return std::make_unique<HogPeer>(upscale); }

std::unique_ptr<PersonPeer> makeHaarFullbodyPeer(const std::filesystem::path& cascadeFile, double upscale) {
  return std::make_unique<HaarPeer>(cascadeFile, upscale);
}

std::filesystem::path defaultHaarFullbodyPath() {
  return "/usr/share/opencv4/haarcascades/haarcascade_fullbody.xml";
}

}  // namespace fusedet::tools::experiments
