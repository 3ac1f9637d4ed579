// SPDX-License-Identifier: Apache-2.0
// fusedet demo: the main job on its embedded default - the most complete pipeline that exists,
// run on the real KITTI frames in ../shared/data: read a frame, fuse it into a layer stack
// (fusion/), print the stack and the labels, and detect with the bundled models (boost/).

#include <Eigen/Core>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <opencv2/core.hpp>

#include "command.h"
#include "data_dir.h"
#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/data_split.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/core/layer_stack.h"
#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/projection.h"

namespace fusedet::tools {
namespace {

struct DemoOptions {
  std::filesystem::path data = defaultDataDir();
  std::string drive = "kitti";
  std::string frame;  // empty = the first frame of the drive's last third (a training frame, as all are)
  std::filesystem::path models = "models";  // one model file per class (*.json)
  int threads = 0;
  bool classDetection = true;  // classes grouped with their own settings (class_detection.h), as fusedetd
};

// Detects with every model in `dir` as fusedetd does (one pass, each class grouped with its own
// settings unless `classDetection` is off) and prints each detection with its best-matching label.
void detectWithModels(const std::filesystem::path& dir, const LayerStack& stack, const Labels& labels,
                      int threads, bool classDetection) {
  std::vector<std::filesystem::path> files;
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(dir, ec))
    if (e.path().extension() == ".json") files.push_back(e.path());
  if (ec || files.empty())
    throw std::runtime_error(dir.string() + ": no model files (*.json); set --models");
  std::sort(files.begin(), files.end());
  // fusedetd's defaults (ScanParams{}, GroupParams{}: scale factor 1.1, step 2, OpenCV grouping
  // with 3 neighbours, no laser extent) and the classes' own groupings (class_detection.h).
  boosting::ScanParams scan;
  scan.threads = threads;
  const boosting::GroupParams group;
  const boosting::LaserExtentParams extent;
  std::vector<boosting::Cascade> models;
  for (const auto& file : files) models.push_back(boosting::loadModel(file));
  const boosting::MultiDetector detector(std::move(models));
  const std::vector<boosting::ClassGrouping> perClass =
      classDetection ? boosting::classGroupings(detector, group, extent) : std::vector<boosting::ClassGrouping>{};
  // Every class in one pass over the stack (shared integrals, one pool of work for the threads).
  const auto t0 = std::chrono::steady_clock::now();
  boosting::PerClassWork work;
  const std::vector<Detection> all = boosting::detectPerClass(detector, stack, scan, group, extent, perClass, &work);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  std::printf("detect    %zu classes in one pass (scan, grouping, laser extent): %.1f ms\n", detector.size(), ms);
  std::size_t first = 0;
  for (std::size_t i = 0; i < detector.size(); ++i) {
    const auto& c = detector.cascade(i);
    const boosting::GroupingOfClass g = boosting::groupingFor(c.className, perClass, group, extent);
    std::printf("detect    %-7s %s: %zu stages, %zu detections (%s grouping: %d neighbours, laser extent %s)\n",
                c.className.c_str(), files[i].filename().string().c_str(), c.stages.size(), work.detections[i],
                g.own ? "its own" : "general", g.group.minNeighbors, g.extent.enabled ? "on" : "off");
    for (std::size_t n = first; n < first + work.detections[i]; ++n) {
      const Detection& d = all[n];
      double best = 0;
      const Label* match = nullptr;
      for (const Label& l : labels) {
        const double v = iou(d.box, l.box);
        if (v > best) best = v, match = &l;
      }
      std::printf("  %-7s score=%7.3f box x=%.1f y=%.1f w=%.1f h=%.1f", d.className.c_str(), d.score, d.box.x,
                  d.box.y, d.box.w, d.box.h);
      if (match && best >= 0.5)
        std::printf("  matches %s label (IoU %.2f)\n", match->sourceClass.c_str(), best);
      else
        std::printf("  no label with IoU >= 0.5\n");
    }
    first += work.detections[i];
  }
}

int runDemo(const DemoOptions& o) {
  const auto root = o.data / o.drive;
  if (!std::filesystem::is_directory(root))
    throw std::runtime_error(root.string() + ": no such data directory (set --data or FUSEDET_DATA)");
  const auto ids = fusion::listKittiFrames(root);
  if (ids.empty()) throw std::runtime_error(root.string() + ": no frames");
  const std::string id = o.frame.empty() ? ids[std::min(boosting::firstTestFrame(ids.size()), ids.size() - 1)] : o.frame;
  const fusion::KittiFrame f = fusion::readKittiFrame(root, id);

  std::printf("fusedet demo: KITTI %s frame %s (%zu frames in drive)\n", o.drive.c_str(), id.c_str(),
              ids.size());
  std::printf("camera    %d x %d BGR\n", f.image.cols, f.image.rows);

  // Points in front of the camera that land inside the image: the part fusion will use.
  const Eigen::Matrix<double, 3, 4> P = f.calib.veloToImage();
  std::size_t inImage = 0;
  double minRange = INFINITY, maxRange = 0, meanRemission = 0;
  for (const auto& p : f.points.points) {
    const Eigen::Vector3d x = P * Eigen::Vector4d(p.x, p.y, p.z, 1);
    if (x.z() <= 0) continue;
    const double u = x.x() / x.z(), v = x.y() / x.z();
    if (u < 0 || v < 0 || u >= f.image.cols || v >= f.image.rows) continue;
    ++inImage;
    const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
    minRange = std::min(minRange, r);
    maxRange = std::max(maxRange, r);
    meanRemission += p.remission;
  }
  std::printf("velodyne  %zu points, %zu project into the image (range %.2f..%.2f m, mean remission %.3f)\n",
              f.points.size(), inImage, minRange, maxRange, inImage ? meanRemission / inImage : 0.0);

  // The fusion step: the same code the live pipeline and `fusedet import-kitti` run.
  const fusion::Fuser fuser = fusion::kittiFuser(f.calib, f.image.cols, f.image.rows);
  fusion::FuseTimings t;
  const LayerStack stack = fuser.fuse(f.image, f.points, &t);
  std::printf("fused     in %.1f ms, first call (undistort %.2f, camera layers %.2f, project %.2f, rasterise + fill %.2f)\n",
              t.totalMs, t.undistortMs, t.cameraLayersMs, t.projectMs, t.rasteriseMs);
  std::printf("stack     %zu layers, reference %d x %d; laser layers at scale %.2f, holes filled up to %d cells\n",
              stack.size(), stack.width(), stack.height(), fuser.config().laserLayerScale,
              fuser.config().holeFillRadius);
  std::printf("  %-10s %-11s %-4s %7s %9s %9s %9s\n", "layer", "size", "type", "valid", "min", "max", "mean");
  for (const Layer& l : stack.layers()) {
    const cv::Mat mask = l.hasMask() ? l.valid : cv::Mat();
    double lo = 0, hi = 0;
    cv::minMaxLoc(l.data, &lo, &hi, nullptr, nullptr, mask.empty() ? cv::noArray() : cv::InputArray(mask));
    const double mean = cv::mean(l.data, mask.empty() ? cv::noArray() : cv::InputArray(mask))[0];
    const double valid = l.hasMask() ? 100.0 * cv::countNonZero(l.valid) / static_cast<double>(l.valid.total()) : 100.0;
    const char* type = l.data.depth() == CV_8U ? "u8" : l.data.depth() == CV_16U ? "u16" : "f32";
    char size[32];
    std::snprintf(size, sizeof size, "%d x %d", l.width(), l.height());
    std::printf("  %-10s %-11s %-4s %6.1f%% %9.3f %9.3f %9.3f", l.name.c_str(), size, type, valid, lo, hi, mean);
    if (l.hasMask())
      std::printf("  (measured %.1f%%, filled %.1f%%)",
                  100.0 * cv::countNonZero(l.valid == fusion::kMaskMeasured) / static_cast<double>(l.valid.total()),
                  100.0 * cv::countNonZero(l.valid == fusion::kMaskFilled) / static_cast<double>(l.valid.total()));
    std::printf("\n");
  }

  std::map<std::string, int> counts;
  for (const Label& l : f.labels) counts[l.ignore ? "ignore(" + l.sourceClass + ")" : l.className]++;
  std::printf("labels    %zu:", f.labels.size());
  for (const auto& [name, n] : counts) std::printf(" %s=%d", name.c_str(), n);
  std::printf("\n");
  for (const Label& l : f.labels)
    if (!l.ignore)
      std::printf("  %-7s box x=%.1f y=%.1f w=%.1f h=%.1f occlusion=%d\n", l.className.c_str(), l.box.x,
                  l.box.y, l.box.w, l.box.h, l.occlusion);
  if (!o.models.empty()) detectWithModels(o.models, stack, f.labels, o.threads, o.classDetection);
  return 0;
}

const bool registered = registerCommand(
    "demo",
    "Fuse one real KITTI frame into a layer stack, print it and detect with the bundled models",
    [](CLI::App& app) {
      auto o = std::make_shared<DemoOptions>();
      app.add_option("--data", o->data, "root of the shared data (kitti/, kitti_0009/, ...)")
          ->capture_default_str();
      app.add_option("--drive", o->drive, "drive directory under --data")->capture_default_str();
      app.add_option("--frame", o->frame,
                     "frame id, e.g. 000042 (default: the first frame of the drive's last third, kitti/000105)");
      app.add_option("--models", o->models,
                     "directory of model files (*.json) to detect with; empty string = fuse only")
          ->capture_default_str();
      app.add_option("--threads", o->threads, "detection threads; 0 = all cores")->capture_default_str();
      app.add_flag("!--no-class-detection", o->classDetection,
                   "group every class with the general settings (3 neighbours, no laser extent), car included; by "
                   "default each class with settings of its own (fusedet/boost/class_detection.h: car 16 "
                   "neighbours and laser extent) gets them, as in fusedetd's built-in detection.classes");
      app.footer(
          "Reads image_2, velodyne, calib and label_2 of one frame, fuses it (camera layers red, green,\n"
          "blue, intensity, hue at image size; distance and remission at half size with a validity\n"
          "mask) and prints each layer's size, type, valid share and value range, then the labels.\n"
          "Then runs every model in --models (the bundled models/<class>.json by default) on the stack\n"
          "as fusedetd does with its built-in settings: one pass at scale factor 1.1, step 2, then each\n"
          "class grouped by OpenCV's rule - car with its own settings (16 neighbours, boxes widened to the\n"
          "laser's object; fusedet/boost/class_detection.h, docs/results, \"Options\"), person and bike with\n"
          "3 neighbours and no laser extent (--no-class-detection: every class so). Prints the time of that\n"
          "pass, each class's settings and each detection with the label it matches (IoU >= 0.5), if\n"
          "any. The bundled models are trained on every shared frame, the demo frames included: the\n"
          "demo shows the pipeline at work, not accuracy on unseen streets (docs/results has the\n"
          "cross-drive figures).\n\n"
          "Examples:\n"
          "  fusedet demo\n"
          "  fusedet demo --drive kitti_0009 --frame 000004\n"
          "  fusedet demo --frame 000060 --no-class-detection   # car grouped as person and bike\n"
          "  FUSEDET_DATA=/data/kitti-root fusedet demo --drive kitti");
      return [o] { return runDemo(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
