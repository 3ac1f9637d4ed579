// SPDX-License-Identifier: Apache-2.0
// All three bundled classes (models/car.json, person.json, bike.json) on one real fused KITTI
// stack - the frame `fusedet demo` detects on - in one pass (scale factor 1.1, step 2) grouped two
// ways: every class with the general settings (detect(): OpenCV grouping, 3 neighbours, no laser
// extent) and as fusedetd, demo and detect do (detectPerClass() with classGroupings(): car with 16
// neighbours and its boxes widened to the laser's object, fusedet/boost/class_detection.h); and two
// yardsticks measured in the same process, interleaved round by round so that the load of a shared
// machine hits all alike:
//   - the previous per-class path: each model on its own integrals, scanned one window at a time
//     (Detector::scan(IntegralStack)), then grouped: what detection cost before the one-pass scanner;
//   - cv::CascadeClassifier with haarcascade_frontalface_default.xml on the same stack's intensity
//     layer, the same scale factor 1.1 and minNeighbors 3 (a peer doing comparable work, as a
//     yardstick for the machine: a ratio to it travels between machines better than milliseconds).
// Times are the calling thread's CPU time (CLOCK_THREAD_CPUTIME_ID), one thread each unless said,
// median over the rounds; wall times beside them. Ours runs on the vector path the dispatch picks
// (the CPU's widest, narrowed by FUSEDET_SIMD: fusedet/boost/vector_path.h; the CPU's extensions and
// the path are printed first) and, row by row, on every path the CPU has (AVX-512, AVX2, scalar)
// within FUSEDET_SIMD, each with its share of time in the integrals (the same on every path), the
// window scan (the vector stage loops) and the rest (grouping). The 2-thread run reports wall time
// (its work is split over two threads) and the scaling against one thread.
//
// With neural layers (issue 30; --networks, default ../shared/models): in the same rounds, each
// network (Yolo-Fastest-XL, Darknet, 832x256; YOLOv5n, ONNX, 832x256) run once on the stack's
// camera image with its score layers added (fusion::NeuralLayers::add, what fusedetd's network
// thread does per stack), one OpenCV thread; and the stack's whole cost with them: that plus
// fusedetd's path on the stack that has the network's layers (the bundled models do not read them:
// a model trained on them scans the same windows).
//
// Headline: bench: detect3_ms, bench: detect3_daemon_path_ms (detectPerClass, the path fusedetd runs),
// bench: opencv_face_ms, bench: detect3_over_opencv_face, bench: detect3_daemon_path_over_opencv_face
// (all on the dispatched path); per path P (avx512, avx2, scalar): detect3_P_ms, detect3_P_over_opencv_face;
// per network N (darknet_832x256, yolov5n_832x256): neural_N_ms (the network and its layers),
// detect3_daemon_path_plus_neural_N_ms.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <memory>
#include <opencv2/core/utility.hpp>
#include <opencv2/objdetect.hpp>
#include <stdexcept>
#include <string>
#include <thread>
#include <tuple>
#include <vector>

#include <CLI/CLI.hpp>

#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/grouping.h"
#include "fusedet/boost/integral_grids.h"
#include "fusedet/boost/model_io.h"
#include "fusedet/boost/multi_detector.h"
#include "fusedet/boost/vector_path.h"
#include "fusedet/boost/window_scanner.h"
#include "fusedet/core/cpu_time.h"
#include "fusedet/fusion/camera_layers.h"
#include "fusedet/fusion/datasets/kitti.h"
#include "fusedet/fusion/neural/neural_layers.h"

namespace {

namespace fs = std::filesystem;
using namespace fusedet;
using namespace fusedet::boosting;

const fs::path kFace = "/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml";

double wallMs() {
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

struct Timing {
  std::vector<double> cpu, wall, processCpu;
  void add(const std::function<void()>& f) {
    const double c0 = threadCpuMs(), p0 = processCpuMs(), w0 = wallMs();
    f();
    cpu.push_back(threadCpuMs() - c0);
    processCpu.push_back(processCpuMs() - p0);
    wall.push_back(wallMs() - w0);
  }
};
double median(std::vector<double> v) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}
double minimum(const std::vector<double>& v) { return v.empty() ? 0 : *std::min_element(v.begin(), v.end()); }

std::string loadAverage() {
  std::ifstream in("/proc/loadavg");
  std::string a, b, c;
  in >> a >> b >> c;
  return a + " " + b + " " + c;
}

struct Args {
  int rounds = 15;
  fs::path data = FUSEDET_DATA_DIR;
  fs::path models = FUSEDET_MODELS_DIR;
  fs::path networks = FUSEDET_NETWORKS_DIR;
  std::string drive = "kitti";
};

// Command line (CLI11); exits after --help (0) or a bad argument (non-zero).
Args parse(int argc, char** argv) {
  Args a;
  CLI::App app{
      "bench_detect3 - the three bundled models on the demo frame, the first of the drive's last third (fused), one pass, vs\n"
      "the previous per-class path and vs OpenCV's frontalface_default on the intensity layer, rounds\n"
      "interleaved; medians of thread CPU time."};
  bool smoke = false;
  app.add_option("--rounds", a.rounds, "rounds (each times every contender once)")->check(CLI::PositiveNumber)
      ->capture_default_str();
  app.add_flag("--smoke", smoke, "one round (ctest)");
  app.add_option("--data", a.data, "root of the shared data")->capture_default_str();
  app.add_option("--drive", a.drive, "KITTI drive folder under --data")->capture_default_str();
  app.add_option("--models", a.models, "folder with car.json, person.json, bike.json")->capture_default_str();
  app.add_option("--networks", a.networks,
                 "folder with the networks of the neural rows: yolo-fastest-1.1-xl.cfg and .weights (Darknet) and\n"
                 "yolov5n_256x832.onnx (YOLOv5n, AGPL-3.0: user-supplied); a network whose files are not there\n"
                 "gets no rows (the reason is printed); empty: no neural rows")
      ->capture_default_str();
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    std::exit(app.exit(e));
  }
  if (smoke) a.rounds = 1;
  return a;
}

}  // namespace

int main(int argc, char** argv) try {
  const Args a = parse(argc, argv);
  cv::setNumThreads(1);
  // The demo's frame: the first of the drive's last third (a training frame of the models).
  const fs::path root = a.data / a.drive;
  const std::vector<std::string> ids = fusion::listKittiFrames(root);
  if (ids.empty()) throw std::runtime_error(root.string() + ": no frames");
  const std::string id = ids[std::min(ids.size() - 1, static_cast<std::size_t>(ids.size() * 2.0 / 3.0 + 0.5))];
  const fusion::KittiFrame f = fusion::readKittiFrame(root, id);
  const LayerStack stack = fusion::kittiFuser(f.calib, f.image.cols, f.image.rows).fuse(f.image, f.points);
  std::vector<Cascade> models;
  for (const char* name : {"car.json", "person.json", "bike.json"}) models.push_back(loadModel(a.models / name));
  const MultiDetector all(models);
  std::vector<Detector> each;
  for (const Cascade& c : models) each.emplace_back(c);
  cv::CascadeClassifier face;
  if (!face.load(kFace.string())) throw std::runtime_error("cannot load " + kFace.string());
  const cv::Mat& intensity = stack.at("intensity").data;

  ScanParams scan;
  scan.scaleFactor = 1.1;
  scan.step = 2;
  scan.threads = 1;
  GroupParams group;
  group.minNeighbors = 3;
  const LaserExtentParams noExtent;  // the general setting: off
  const std::vector<ClassGrouping> perClass = classGroupings(all, group, noExtent);  // fusedetd's defaults
  std::string perClassText;
  for (const ClassGrouping& k : perClass)
    perClassText += (perClassText.empty() ? "" : "; ") + k.className + " with minNeighbors " +
                    std::to_string(k.minNeighbors) + " and laser extent " + (k.laserExtent ? "on" : "off");
  std::printf("stack %s/%s: %d x %d, %zu layers; models car, person, bike; scale factor 1.1, step 2, minNeighbors 3\n"
              "fusedetd's path (detectPerClass, as fusedetd, demo and detect run): the same pass, grouped %s, the others as above\n",
              a.drive.c_str(), id.c_str(), stack.width(), stack.height(), stack.size(), perClassText.c_str());
  std::printf("load average before: %s (%u cores)\n", loadAverage().c_str(), std::thread::hardware_concurrency());
  const int dispatched = dispatchedVectorLanes();
  std::printf("dispatched: %s\n", vectorPathSummary().c_str());
  // Every path the CPU has within FUSEDET_SIMD, widest first.
  std::vector<int> paths;
  for (int lanes : {8, 4, 1}) {
    setVectorLanesLimit(lanes);
    if (dispatchedVectorLanes() == lanes) paths.push_back(lanes);
  }
  setVectorLanesLimit(8);
  std::vector<LayerRequest> requests;
  std::vector<const Cascade*> cascades;
  for (const Cascade& c : models) {
    cascades.push_back(&c);
    for (LayerRequest& r : layerRequests(c)) requests.push_back(std::move(r));
  }

  // Same decisions: the one-pass scanner's raw hits against the previous per-class path's.
  std::vector<ScanStats> stats;
  const auto hits = all.scan(stack, scan, &stats);
  std::size_t windows = 0, stumps = 0, same = 0, total = 0;
  for (std::size_t i = 0; i < models.size(); ++i) {
    const auto ref = each[i].scan(integrateFor(models[i], stack), scan);
    total += ref.size();
    bool eq = ref.size() == hits[i].size();
    for (std::size_t k = 0; eq && k < ref.size(); ++k)
      eq = ref[k].box == hits[i][k].box && ref[k].score == hits[i][k].score;
    same += eq ? 1 : 0;
    windows += stats[i].windows;
    stumps += stats[i].stumps;
    std::printf("  %-7s %zu stages, %8zu windows, %.2f weak classifiers/window, %zu raw hits (per-class path: %zu, %s)\n",
                models[i].className.c_str(), models[i].stages.size(), stats[i].windows,
                double(stats[i].stumps) / double(stats[i].windows), hits[i].size(), ref.size(),
                eq ? "identical" : "DIFFERENT");
  }

  // The networks of the neural rows, each with the stack it makes (the demo stack + its layers).
  struct NeuralRow {
    std::string key, what;
    std::unique_ptr<fusion::NeuralLayers> layers;
    LayerStack stack;
    Timing run, detect;
    std::size_t found = 0;
  };
  std::vector<NeuralRow> neural;
  const cv::Mat cameraBgr = fusion::cameraImage(stack);
  if (!a.networks.empty())
    for (const auto& [kind, key, what] : {std::tuple{fusion::NetworkKind::darknet, "darknet_832x256", "Yolo-Fastest-XL (Darknet) 832x256"},
                                         std::tuple{fusion::NetworkKind::yolov5Onnx, "yolov5n_832x256", "YOLOv5n (ONNX) 832x256"}}) {
      fusion::NeuralLayerOptions o;
      o.kind = kind;
      o.directory = a.networks;
      try {
        NeuralRow row{key, what, std::make_unique<fusion::NeuralLayers>(o), stack, {}, {}, 0};
        row.layers->add(row.stack, cameraBgr);
        neural.push_back(std::move(row));
      } catch (const std::exception& e) {
        std::printf("neural rows of %s: none (%s)\n", what, e.what());
      }
    }

  Timing ours, ours2, previous, opencv, daemonPath, integrals;
  std::vector<Timing> pathTotal(paths.size()), pathScan(paths.size());
  std::size_t found = 0, foundPrev = 0, faces = 0, foundDaemonPath = 0;
  for (int r = 0; r < a.rounds; ++r) {
    ours.add([&] { found = detect(all, stack, scan, group).size(); });
    daemonPath.add([&] { foundDaemonPath = detectPerClass(all, stack, scan, group, noExtent, perClass).size(); });
    opencv.add([&] {
      std::vector<cv::Rect> out;
      face.detectMultiScale(intensity, out, 1.1, 3);
      faces = out.size();
    });
    previous.add([&] {
      foundPrev = 0;
      for (std::size_t i = 0; i < models.size(); ++i)
        foundPrev += groupHits(each[i].scan(integrateFor(models[i], stack), scan), group, models[i].className, stack).size();
    });
    integrals.add([&] { (void)IntegralGrids(stack, requests, 1); });
    {
      const IntegralGrids grids(stack, requests, 1);
      for (std::size_t k = 0; k < paths.size(); ++k) {
        setVectorLanesLimit(paths[k]);
        pathTotal[k].add([&] { (void)detect(all, stack, scan, group); });
        pathScan[k].add([&] { (void)scanCascades(cascades, grids, scan, nullptr); });
      }
      setVectorLanesLimit(8);
    }
    ScanParams two = scan;
    two.threads = 2;
    ours2.add([&] { (void)detect(all, stack, two, group); });
    for (NeuralRow& n : neural) {
      LayerStack withLayers = stack;
      n.run.add([&] { n.layers->add(withLayers, cameraBgr); });
      n.detect.add([&] { n.found = detectPerClass(all, n.stack, scan, group, noExtent, perClass).size(); });
    }
  }
  const double d3 = median(ours.cpu), cvf = median(opencv.cpu), prev = median(previous.cpu),
               d3k = median(daemonPath.cpu);
  std::printf("%d rounds, interleaved; thread CPU ms median (min) / wall ms median:\n", a.rounds);
  std::printf("  ours, 3 classes one pass, 1 thread: %8.2f (%7.2f) / %8.2f  -> %zu detections, %.2f ns per weak classifier\n",
              d3, minimum(ours.cpu), median(ours.wall), found, d3 * 1e6 / double(stumps));
  std::printf("  ours, fusedetd's path, 1 thread:    %8.2f (%7.2f) / %8.2f  -> %zu detections (detectPerClass: car's own grouping)\n", d3k,
              minimum(daemonPath.cpu), median(daemonPath.wall), foundDaemonPath);
  const double integralMs = median(integrals.cpu);
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const double t = median(pathTotal[k].cpu), sc = std::min(t, median(pathScan[k].cpu));
    const double in = std::min(t - sc, integralMs);
    std::printf("  ours, same, %-6s path (%d lane%s): %8.2f (%7.2f) / %8.2f  -> %.3f x OpenCV; integrals %2.0f %%, scan %2.0f %%, "
                "grouping and the rest %2.0f %%\n",
                vectorPathName(paths[k]).c_str(), paths[k], paths[k] > 1 ? "s" : " ", t, minimum(pathTotal[k].cpu),
                median(pathTotal[k].wall), cvf > 0 ? t / cvf : 0.0, 100 * in / t, 100 * sc / t, 100 * (t - sc - in) / t);
  }
  std::printf("  previous per-class path, 1 thread:  %8.2f (%7.2f) / %8.2f  -> %zu detections\n", prev,
              minimum(previous.cpu), median(previous.wall), foundPrev);
  std::printf("  OpenCV frontalface_default, 1 thr:  %8.2f (%7.2f) / %8.2f  -> %zu faces (intensity layer %dx%d)\n",
              cvf, minimum(opencv.cpu), median(opencv.wall), faces, intensity.cols, intensity.rows);
  std::printf("  ours, 2 threads: wall %.2f ms (min %.2f), process CPU %.2f ms; scaling vs 1 thread (wall) %.2fx\n",
              median(ours2.wall), minimum(ours2.wall), median(ours2.processCpu),
              median(ours2.wall) > 0 ? median(ours.wall) / median(ours2.wall) : 0.0);
  for (const NeuralRow& n : neural) {
    const double net = median(n.run.cpu), det = median(n.detect.cpu);
    std::printf("  neural layers, %-34s %8.2f (%7.2f) / %8.2f  -> the network on the %dx%d image + 3 score layers, 1 OpenCV thread\n",
                (n.what + ":").c_str(), net, minimum(n.run.cpu), median(n.run.wall), cameraBgr.cols, cameraBgr.rows);
    std::printf("  fusedetd's path on that stack + the network: %8.2f / %8.2f  -> %zu detections (%zu layers; %.3f x OpenCV)\n",
                det + net, median(n.detect.wall) + median(n.run.wall), n.found, n.stack.size(), cvf > 0 ? (det + net) / cvf : 0.0);
  }
  std::printf("equal terms: every contender on the same fused stack in the same process, rounds interleaved, one\n"
              "thread each (cv::setNumThreads(1)), thread CPU time; the per-class path scans the same models with the\n"
              "same scales, step and grouping (its hits checked identical above); OpenCV runs frontalface_default on\n"
              "the stack's intensity layer with the same scale factor 1.1 and minNeighbors 3 and its own window step\n"
              "(2 pixels below scale 2, then 1): a different cascade, so a yardstick of the machine, not the same work;\n"
              "fusedetd's path does the same scan as the first row and groups car with 16 neighbours and then\n"
              "widens car's boxes to the laser's object (fusedet/boost/laser_extent.h): OpenCV's peer has no\n"
              "laser layer and no laser extent step, so that part of fusedetd's path is work the peer does not\n"
              "do; fusedetd runs it on all cores (detection.threads 0), here on one thread like every other\n"
              "1-thread row\n");
  std::printf("load average after: %s\n", loadAverage().c_str());
  std::printf("bench: detect3_identical_to_per_class %d\n", same == models.size() ? 1 : 0);
  std::printf("bench: detect3_previous_ms %.3f\n", prev);
  std::printf("bench: detect3_speedup_vs_previous %.3f\n", d3 > 0 ? prev / d3 : 0.0);
  std::printf("bench: detect3_2threads_wall_ms %.3f\n", median(ours2.wall));
  std::printf("bench: detect3_vector_lanes %d\n", dispatched);
  for (std::size_t k = 0; k < paths.size(); ++k) {
    const std::string name = vectorPathName(paths[k]);
    std::printf("bench: detect3_%s_ms %.3f\n", name.c_str(), median(pathTotal[k].cpu));
    std::printf("bench: detect3_%s_over_opencv_face %.3f\n", name.c_str(), cvf > 0 ? median(pathTotal[k].cpu) / cvf : 0.0);
  }
  std::printf("bench: detect3_ms %.3f\n", d3);
  std::printf("bench: detect3_daemon_path_ms %.3f\n", d3k);
  std::printf("bench: opencv_face_ms %.3f\n", cvf);
  std::printf("bench: detect3_over_opencv_face %.3f\n", cvf > 0 ? d3 / cvf : 0.0);
  std::printf("bench: detect3_daemon_path_over_opencv_face %.3f\n", cvf > 0 ? d3k / cvf : 0.0);
  for (const NeuralRow& n : neural) {
    std::printf("bench: neural_%s_ms %.3f\n", n.key.c_str(), median(n.run.cpu));
    std::printf("bench: detect3_daemon_path_plus_neural_%s_ms %.3f\n", n.key.c_str(), median(n.detect.cpu) + median(n.run.cpu));
  }
  return same == models.size() ? 0 : 1;
} catch (const std::exception& e) {
  std::fprintf(stderr, "bench_detect3: error: %s\n", e.what());
  return 1;
}
