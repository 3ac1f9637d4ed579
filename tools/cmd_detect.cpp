// SPDX-License-Identifier: Apache-2.0
// fusedet detect: run one cascade - ours (model file from `fusedet train`) or an OpenCV Haar
// cascade XML - on an image or a data-set stack, and print / save / draw the detections.

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <regex>

#include "command.h"
#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/detector.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/laser_extent.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/boost/opencv_cascade.h"
#include "fusedet/core/dataset.h"
#include "fusedet/fusion/camera_layers.h"
#include "fusedet/fusion/drawing/box_drawing.h"
#include "network_options.h"

namespace fusedet::tools {
namespace {

namespace fs = std::filesystem;
using namespace fusedet::boosting;

struct DetectOptions {
  fs::path model;
  fs::path image;
  fs::path stack;
  std::string item;
  fs::path json;
  fs::path draw;
  std::optional<double> scaleFactor;
  std::optional<int> minNeighbors;  // given: for every class
  bool laserExtent = false;         // given: on for every class
  bool classDetection = true;       // a class with settings of its own gets them (class_detection.h)
  std::string minSize, maxSize;
  double step = 2;
  int threads = 0;
  NetworkOptions network;
};

bool isOpenCvXml(const fs::path& p) {
  std::string ext = p.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext == ".xml";
}

// "WxH" -> (w, h), both >= 1.
std::pair<int, int> parseSize(const std::string& s, const char* option) {
  static const std::regex re("^([0-9]{1,5})x([0-9]{1,5})$");
  std::smatch m;
  if (!std::regex_match(s, m, re) || std::stoi(m[1]) < 1 || std::stoi(m[2]) < 1)
    throw std::runtime_error(std::string(option) + " '" + s + "': expected WxH in pixels, e.g. 24x24");
  return {std::stoi(m[1]), std::stoi(m[2])};
}

// A data set item given as DATASET (with --item, default the first) or as DATASET/items/<id>.
DatasetItem readStack(const fs::path& s, const std::string& item) {
  if (fs::exists(s / "dataset.json")) {
    const std::string id = item.empty() ? listDataset(s).at(0) : item;
    return readDatasetItem(s, id);
  }
  fs::path dir = fs::absolute(s).lexically_normal();
  fs::path id;
  for (fs::path p = dir; p.has_relative_path() && p != p.parent_path(); p = p.parent_path()) {
    if (p.filename() == "items" && fs::exists(p.parent_path() / "dataset.json"))
      return readDatasetItem(p.parent_path(), fs::relative(dir, p).generic_string());
  }
  throw std::runtime_error(s.string() + ": not a data set directory (no dataset.json) nor an item directory "
                           "DATASET/items/<id>");
}

// Something to draw on: the colour image, else red/green/blue, else intensity of the stack.
cv::Mat canvasOf(const LayerStack& stack, const cv::Mat& bgr) {
  if (!bgr.empty()) return bgr.clone();
  cv::Mat out;
  auto eight = [](const cv::Mat& m) {
    cv::Mat o;
    if (m.depth() == CV_8U) return m;
    cv::normalize(m, o, 0, 255, cv::NORM_MINMAX, CV_8U);
    return o;
  };
  if (fusion::hasCameraImage(stack)) {
    out = fusion::cameraImage(stack);
  } else if (stack.has("intensity")) {
    cv::cvtColor(eight(stack.at("intensity").data), out, cv::COLOR_GRAY2BGR);
  } else if (stack.size() > 0) {
    cv::cvtColor(eight(stack.layers()[0].data), out, cv::COLOR_GRAY2BGR);
  }
  if (!out.empty() && (out.cols != stack.width() || out.rows != stack.height()))
    cv::resize(out, out, cv::Size(stack.width(), stack.height()), 0, 0, cv::INTER_NEAREST);
  return out;
}

int runDetect(const DetectOptions& o) {
  if (o.image.empty() == o.stack.empty()) throw std::runtime_error("give exactly one of --image and --stack");
  const bool opencv = isOpenCvXml(o.model);
  Cascade cascade = opencv ? loadOpenCvCascade(o.model) : loadModel(o.model);
  // One model through the path fusedetd runs for all of them (detectPerClass, same decisions).
  const MultiDetector detector({std::move(cascade)});
  const Cascade& c = detector.cascade(0);

  LayerStack stack;
  cv::Mat bgr;
  if (!o.image.empty()) {
    bgr = cv::imread(o.image.string(), cv::IMREAD_COLOR);
    if (bgr.empty()) throw std::runtime_error(o.image.string() + ": cannot read image");
    fusion::addCameraLayers(stack, bgr);  // red, green, blue, intensity (= cv::COLOR_BGR2GRAY), hue
    stack.source = o.image.string();
  } else {
    stack = readStack(o.stack, o.item).stack;
  }
  // The network's score layers, made by the code import and fusedetd use, from the stack's camera
  // image (replacing any the stack has): the model then checks that they come from its network.
  if (const auto neural = o.network.load()) neural->add(stack, bgr.empty() ? fusion::cameraImage(stack) : bgr);
  for (const std::string& l : c.layers) {
    const bool derivable = l == "hue_distance" && stack.has("hue");
    if (!stack.has(l) && !derivable)
      throw std::runtime_error(o.model.string() + " needs layer '" + l + "', which " +
                               (o.image.empty() ? o.stack.string() : o.image.string() + " (an image gives camera layers only)") +
                               " lacks" +
                               (isNetworkLayer(l) ? std::string("; give the network that made the model's layers: ") +
                                                        (c.network.empty() ? std::string("--network ...")
                                                                           : "--network " + c.network.text())
                                                  : std::string()));
  }

  ScanParams scan;
  scan.scaleFactor = o.scaleFactor.value_or(1.1);
  if (!(scan.scaleFactor > 1.0)) throw std::runtime_error("--scale-factor must be > 1");
  scan.step = o.step;
  scan.threads = o.threads;
  if (!o.minSize.empty()) std::tie(scan.minWidth, scan.minHeight) = parseSize(o.minSize, "--min-size");
  if (!o.maxSize.empty()) std::tie(scan.maxWidth, scan.maxHeight) = parseSize(o.maxSize, "--max-size");
  GroupParams group;
  group.minNeighbors = o.minNeighbors.value_or(group.minNeighbors);
  LaserExtentParams extent;
  extent.enabled = o.laserExtent;
  // The model's class gets its own min neighbours / laser extent (car) unless the option was given.
  const SetForEveryClass given{false, false, o.minNeighbors.has_value(), o.laserExtent};
  const std::vector<ClassGrouping> perClass =
      o.classDetection ? classGroupings(detector, group, extent, given) : std::vector<ClassGrouping>{};
  const GroupingOfClass grouping = groupingFor(c.className, perClass, group, extent);

  const auto t0 = std::chrono::steady_clock::now();
  PerClassWork work;
  const std::vector<Detection> dets = detectPerClass(detector, stack, scan, group, extent, perClass, &work);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

  std::printf("%s on %s (%dx%d): %zu windows at %zu scales, %zu raw hits, %zu detections, %.1f ms\n",
              o.model.filename().string().c_str(), (o.image.empty() ? o.stack : o.image).string().c_str(),
              stack.width(), stack.height(), work.scans[0].windows, work.scans[0].scales, work.rawHits[0], dets.size(),
              ms);
  std::printf("  %s grouping: %d neighbours, laser extent %s\n", grouping.own ? "class's own" : "general",
              grouping.group.minNeighbors, grouping.extent.enabled ? "on" : "off");
  for (const Detection& d : dets)
    std::printf("  %s score %.4g  x %.0f y %.0f w %.0f h %.0f\n", d.className.c_str(), d.score, d.box.x, d.box.y,
                d.box.w, d.box.h);

  if (!o.json.empty()) {
    nlohmann::json arr = nlohmann::json::array();
    for (const Detection& d : dets)
      arr.push_back({{"class", d.className}, {"score", d.score}, {"x", d.box.x}, {"y", d.box.y}, {"w", d.box.w},
                     {"h", d.box.h}});
    std::ofstream out(o.json);
    out << nlohmann::json{{"detections", arr}}.dump(2) << "\n";
    if (!out) throw std::runtime_error(o.json.string() + ": cannot write");
  }
  if (!o.draw.empty()) {
    cv::Mat canvas = canvasOf(stack, bgr);
    fusion::drawBoxes(canvas, 1.0, {}, dets);
    if (canvas.empty() || !cv::imwrite(o.draw.string(), canvas))
      throw std::runtime_error(o.draw.string() + ": cannot write image");
  }
  return 0;
}

const bool registered = registerCommand(
    "detect",
    "Run a cascade (our model file or an OpenCV Haar XML) on an image or a stack and report detections",
    [](CLI::App& app) {
      auto o = std::make_shared<DetectOptions>();
      app.add_option("--model,-m", o->model,
                     "cascade to run: an OpenCV Haar cascade (*.xml, e.g. /usr/share/opencv4/haarcascades/"
                     "haarcascade_frontalface_default.xml; runs on the intensity layer with OpenCV's image pyramid and "
                     "gives cv::CascadeClassifier's decisions) or one of our model files (fusedet train; any other "
                     "extension)")
          ->required()
          ->check(CLI::ExistingFile);
      app.add_option("--image,-i", o->image,
                     "image file (PNG, JPEG, ...): gives the camera layers red, green, blue, intensity, hue (and "
                     "hue_distance for models with a reference hue)")
          ->check(CLI::ExistingFile);
      app.add_option("--stack,-s", o->stack,
                     "layer stack of a data set (docs/dataset-format.md): the data set directory (first item, or "
                     "--item) or an item directory DATASET/items/<id>; needed for laser layers");
      app.add_option("--item", o->item, "item id for --stack DATASET, e.g. kitti/000042");
      app.add_option("--json", o->json,
                     "write {\"detections\": [{\"class\", \"score\", \"x\", \"y\", \"w\", \"h\"}, ...]} here "
                     "(reference/image pixels; fusedet show --detections reads it)");
      addNetworkOptions(app, o->network,
                        "Needed by a model trained on those layers (its file records the network: the same "
                        "kind, files and input size, or detection refuses the stack).");
      app.add_option("--draw", o->draw, "write the image (or the stack's colour/intensity layers) with boxes drawn");
      app.add_option("--scale-factor", o->scaleFactor,
                     "window size step between scales, > 1 (default 1.1, as OpenCV's detectMultiScale)");
      app.add_option("--min-neighbors", o->minNeighbors,
                     "OpenCV grouping: a detection needs more than this many raw hits; 0 = report raw hits "
                     "ungrouped. Default: the class's own (car 16), else 3 as OpenCV; given, it holds for every "
                     "class, car included");
      app.add_flag("--laser-extent", o->laserExtent,
                   "after grouping, widen each detection's left and right edges to where its object's cluster in the "
                   "distance layer ends (fusedet/boost/laser_extent.h) - needs a --stack with a distance layer. "
                   "Default: the class's own (car on), else off; given, on for every class");
      app.add_flag("!--no-class-detection", o->classDetection,
                   "group with the general settings (--min-neighbors or 3, --laser-extent or off) whatever the "
                   "model's class; by default a class with settings of its own (fusedet/boost/class_detection.h: "
                   "car, 16 neighbours and laser extent) gets them for every option not given, as in fusedetd");
      app.add_option("--min-size", o->minSize,
                     "smallest window WxH in image pixels (default: the model's base window)");
      app.add_option("--max-size", o->maxSize, "largest window WxH in image pixels (default: the whole image)");
      app.add_option("--step", o->step,
                     "our models: position step in base-window pixels, scaled with the window (OpenCV models use "
                     "OpenCV's step)")
          ->capture_default_str()
          ->check(CLI::Range(0.01, 1000.0));
      app.add_option("--threads", o->threads, "detection threads, 0 = all cores (output is the same for any count)")
          ->capture_default_str()
          ->check(CLI::Range(0, 1024));
      app.footer(
          "Examples:\n"
          "  fusedet detect -m /usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml \\\n"
          "      -i /usr/share/doc/opencv-doc/examples/data/messi5.jpg --draw faces.png --json faces.json\n"
          "  fusedet detect -m models/car.json --stack data/kitti_set --item kitti/000042\n"
          "  fusedet detect -m eye.xml -i face.png --min-neighbors 0 --min-size 30x30   # raw hits\n"
          "  fusedet detect -m models/car.json --stack data/kitti_set --no-class-detection   # car as person/bike\n"
          "Prints a summary line, the grouping used, then one line per detection (class, score, box in pixels).\n\n"
          "Settings per class: the model's class is grouped as fusedetd groups it (its built-in\n"
          "detection.classes, fusedet/boost/class_detection.h): car with 16 neighbours and its boxes widened\n"
          "to the laser's object (docs/results, \"Options\"), every other class with 3 neighbours and no\n"
          "laser extent. --min-neighbors and --laser-extent, when given, hold for every class instead of its\n"
          "own value; --no-class-detection gives every class the general settings. The scan (scale factor\n"
          "1.1, step 2) is the same for every class. Car's own settings need the laser: on an --image its\n"
          "laser extent leaves the boxes unchanged (no distance layer), its 16 neighbours still apply.");
      return [o] { return runDetect(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
