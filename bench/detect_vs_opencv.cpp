// SPDX-License-Identifier: Apache-2.0
// Our detector vs cv::CascadeClassifier::detectMultiScale (the peer) on the same cascade
// (haarcascade_frontalface_default.xml), the same five photos resized to 640x480, the same scales
// (factor 1.1, no minimum size), raw candidates (minNeighbors 0), both on one thread
// (cv::setNumThreads(1), ScanParams::threads = 1). Also: ns per weak classifier and windows/s of
// one of our multi-layer cascades on a 7-layer stack of KITTI size (1242x375) built from a real
// KITTI image (red, green, blue, intensity, hue) plus two synthetic laser-like layers at quarter
// resolution (distance, remission).
//
// Same decisions, checked on the same run's images: the raw accepted windows of both, as sets (a
// share of all windows scanned would not do: a detector that accepted nothing would score ~1).
//
// Headline lines: bench: detect_speedup_vs_opencv <OpenCV time / our time>
//                 bench: raw_hits_opencv <OpenCV's raw candidates on the five photos>
//                 bench: raw_hits_differ <windows in one set and not the other; 0 = identical sets>

#include <benchmark/benchmark.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/objdetect.hpp>
#include <random>
#include <set>
#include <tuple>

#include "fusedet/boost/detector.h"
#include "fusedet/boost/opencv_cascade.h"

#include "headline_reporter.h"

namespace {

namespace fs = std::filesystem;
using namespace fusedet;
using namespace fusedet::boosting;

const fs::path kCascade = "/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml";
const fs::path kPhotos = "/usr/share/doc/opencv-doc/examples/data";
const fs::path kKitti = fs::path(FUSEDET_DATA_DIR) / "kitti" / "image_2" / "000000.png";

struct Fixture {
  std::vector<cv::Mat> gray;        // 640x480 photos
  std::vector<LayerStack> stacks;   // the same, as intensity layers
  cv::CascadeClassifier opencv;
  std::unique_ptr<Detector> ours;
  LayerStack kitti7;
  std::unique_ptr<Detector> ours7;
};

Fixture& fixture() {
  static Fixture fixt = [] {
    Fixture x;
    for (const char* name : {"messi5.jpg", "baboon.jpg", "home.jpg", "fruits.jpg", "building.jpg"}) {
      const cv::Mat bgr = cv::imread((kPhotos / name).string(), cv::IMREAD_COLOR);
      if (bgr.empty()) throw std::runtime_error("cannot read " + (kPhotos / name).string());
      cv::Mat g, r;
      cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
      cv::resize(g, r, cv::Size(640, 480), 0, 0, cv::INTER_AREA);
      LayerStack s(640, 480);
      s.set(Layer{"intensity", r, {}});
      x.gray.push_back(r);
      x.stacks.push_back(std::move(s));
    }
    if (!x.opencv.load(kCascade.string())) throw std::runtime_error("cannot load " + kCascade.string());
    x.ours = std::make_unique<Detector>(loadOpenCvCascade(kCascade));
    x.kitti7 = [] {
      const cv::Mat bgr = cv::imread(kKitti.string(), cv::IMREAD_COLOR);
      if (bgr.empty()) throw std::runtime_error("cannot read " + kKitti.string());
      LayerStack s(bgr.cols, bgr.rows);
      std::vector<cv::Mat> ch;
      cv::split(bgr, ch);
      s.set(Layer{"red", ch[2], {}});
      s.set(Layer{"green", ch[1], {}});
      s.set(Layer{"blue", ch[0], {}});
      cv::Mat g, hsv, hue;
      cv::cvtColor(bgr, g, cv::COLOR_BGR2GRAY);
      s.set(Layer{"intensity", g, {}});
      cv::cvtColor(bgr, hsv, cv::COLOR_BGR2HSV_FULL);
      cv::extractChannel(hsv, hue, 0);
      hue.convertTo(hue, CV_32F, 360.0 / 256.0);
      s.set(Layer{"hue", hue, {}});
      // Laser-like layers at quarter resolution: distance grows towards the horizon, remission
      // follows the image's brightness; both smooth, as interpolated laser layers are.
      cv::Mat small, dist(bgr.rows / 4, bgr.cols / 4, CV_32F), rem;
      cv::resize(g, small, dist.size(), 0, 0, cv::INTER_AREA);
      for (int y = 0; y < dist.rows; ++y)
        for (int xx = 0; xx < dist.cols; ++xx)
          dist.at<float>(y, xx) = 80.f / (1.f + float(y)) + 0.02f * float(small.at<std::uint8_t>(y, xx));
      small.convertTo(rem, CV_32F, 1.0 / 255.0);
      s.set(Layer{"distance", dist, {}});
      s.set(Layer{"remission", rem, {}});
      return s;
    }();
    x.ours7 = std::make_unique<Detector>([&] {
      // A 20-stage cascade of random features over all 7 layers (hue_distance from hue), each stump
      // split at the median of its feature over sample windows so stages pass about half the time.
      Cascade c;
      c.className = "synthetic";
      c.windowWidth = 32;
      c.windowHeight = 64;
      c.layers = {"red", "green", "blue", "intensity", "hue_distance", "distance", "remission"};
      c.referenceHue = 30;
      const IntegralStack in(x.kitti7, c.layers, c.referenceHue);
      std::mt19937 rng(42);
      std::uniform_real_distribution<double> u(0, 1);
      for (int s = 0; s < 20; ++s) {
        Stage st;
        for (int k = 0; k < 5 + s; ++k) {
          const double fx = u(rng) * 0.7, fy = u(rng) * 0.7;
          const Feature f{static_cast<FeatureType>(rng() % 10), Box{fx, fy, 0.1 + u(rng) * (0.9 - fx), 0.1 + u(rng) * (0.9 - fy)},
                          int(rng() % 7)};
          std::vector<float> v;
          for (int i = 0; i < 201; ++i)
            v.push_back(featureValue(in, f, Box{double(rng() % 1100), double(rng() % 250), 64, 128}));
          std::nth_element(v.begin(), v.begin() + 100, v.end());
          st.stumps.push_back(Stump{c.addFeature(f), v[100], u(rng) < 0.5 ? -1.0 : 1.0, 0});
          st.stumps.back().right = -st.stumps.back().left;
        }
        st.threshold = 0;
        c.stages.push_back(st);
      }
      return c;
    }());
    return x;
  }();
  return fixt;
}

ScanParams singleThread() {
  ScanParams p;
  p.scaleFactor = 1.1;
  p.threads = 1;
  return p;
}

struct Work {
  ScanStats stats;
  std::size_t runs = 0;
};
std::map<std::string, Work> gWork;

void BM_Ours_FrontalFaceDefault_640x480(benchmark::State& state) {
  Fixture& f = fixture();
  Work& w = gWork["ours"];
  for (auto _ : state)
    for (const LayerStack& s : f.stacks) {
      benchmark::DoNotOptimize(f.ours->scan(s, singleThread(), &w.stats));
      ++w.runs;
    }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(f.stacks.size()));
}
BENCHMARK(BM_Ours_FrontalFaceDefault_640x480)->Unit(benchmark::kMillisecond);

void BM_OpenCv_FrontalFaceDefault_640x480(benchmark::State& state) {
  Fixture& f = fixture();
  cv::setNumThreads(1);
  std::vector<cv::Rect> out;
  for (auto _ : state)
    for (const cv::Mat& g : f.gray) {
      f.opencv.detectMultiScale(g, out, 1.1, 0, 0, cv::Size());
      benchmark::DoNotOptimize(out.data());
    }
  state.SetItemsProcessed(int64_t(state.iterations()) * int64_t(f.gray.size()));
}
BENCHMARK(BM_OpenCv_FrontalFaceDefault_640x480)->Unit(benchmark::kMillisecond);

void BM_Ours_7Layer_Kitti_1242x375(benchmark::State& state) {
  Fixture& f = fixture();
  Work& w = gWork["ours7"];
  for (auto _ : state) {
    benchmark::DoNotOptimize(f.ours7->scan(f.kitti7, singleThread(), &w.stats));
    ++w.runs;
  }
}
BENCHMARK(BM_Ours_7Layer_Kitti_1242x375)->Unit(benchmark::kMillisecond);

// The part of the above that builds the 7 integral images (and hue_distance).
void BM_Ours_7Layer_IntegralsOnly(benchmark::State& state) {
  Fixture& f = fixture();
  for (auto _ : state) benchmark::DoNotOptimize(integrateFor(f.ours7->cascade(), f.kitti7));
}
BENCHMARK(BM_Ours_7Layer_IntegralsOnly)->Unit(benchmark::kMillisecond);


// Raw accepted windows (minNeighbors 0) of both on the same images, compared as sets.
struct RawHitSets {
  std::size_t ours = 0, opencv = 0, differ = 0;  // differ: the size of the symmetric difference
};
RawHitSets compareRawHits() {
  Fixture& f = fixture();
  RawHitSets r;
  for (std::size_t i = 0; i < f.gray.size(); ++i) {
    std::vector<cv::Rect> raw;
    f.opencv.detectMultiScale(f.gray[i], raw, 1.1, 0, 0, cv::Size());
    const auto hits = f.ours->scan(f.stacks[i], singleThread());
    std::multiset<std::tuple<int, int, int, int>> a, b;
    for (const cv::Rect& x : raw) a.insert({x.x, x.y, x.width, x.height});
    for (const RawHit& h : hits) b.insert({int(h.box.x), int(h.box.y), int(h.box.w), int(h.box.h)});
    std::vector<std::tuple<int, int, int, int>> d;
    std::set_symmetric_difference(a.begin(), a.end(), b.begin(), b.end(), std::back_inserter(d));
    r.ours += b.size();
    r.opencv += a.size();
    r.differ += d.size();
  }
  return r;
}

}  // namespace

int main(int argc, char** argv) {
  cv::setNumThreads(1);
  benchmark::Initialize(&argc, argv);
  fusedet::bench::HeadlineReporter reporter;
  benchmark::RunSpecifiedBenchmarks(&reporter);
  // Both sides run on one thread, so CPU time is their work; it is also robust against other
  // processes sharing the machine (wall-clock ratio printed beside it).
  const double ours = reporter.cpu["BM_Ours_FrontalFaceDefault_640x480"];
  const double cv = reporter.cpu["BM_OpenCv_FrontalFaceDefault_640x480"];
  const double ours7 = reporter.cpu["BM_Ours_7Layer_Kitti_1242x375"];
  const double integrals7 = reporter.cpu["BM_Ours_7Layer_IntegralsOnly"];
  const double oursWall = reporter.wall["BM_Ours_FrontalFaceDefault_640x480"];
  const double cvWall = reporter.wall["BM_OpenCv_FrontalFaceDefault_640x480"];
  const Work& w = gWork["ours"];
  const Work& w7 = gWork["ours7"];
  const std::size_t images = fixture().gray.size();
  if (w.runs && w.stats.stumps) {
    const double perImageWindows = double(w.stats.windows) / double(w.runs);
    const double perImageStumps = double(w.stats.stumps) / double(w.runs);
    const double msPerImage = ours / double(images);
    std::printf("ours   frontalface_default 640x480: %.2f ms/image (CPU), %.0f windows/image, %.1f weak classifiers/window, "
                "%.2f ns/weak classifier, %.3g windows/s\n",
                msPerImage, perImageWindows, perImageStumps / perImageWindows, msPerImage * 1e6 / perImageStumps,
                perImageWindows / (msPerImage * 1e-3));
    std::printf("opencv frontalface_default 640x480: %.2f ms/image (CPU), %.3f us/window\n", cv / double(images),
                cv / double(images) * 1e3 / perImageWindows);
  }
  if (w7.runs && w7.stats.stumps) {
    const double win = double(w7.stats.windows) / double(w7.runs), st = double(w7.stats.stumps) / double(w7.runs);
    std::printf("ours   7-layer 1242x375 (20 stages, %zu weak classifiers): %.2f ms/stack (CPU), %.0f windows, "
                "%.1f weak classifiers/window, %.2f ns/weak classifier, %.3g windows/s\n",
                fixture().ours7->cascade().weakCount(), ours7, win, st / win, ours7 * 1e6 / st, win / (ours7 * 1e-3));
    std::printf("ours   7-layer: integral images %.2f ms of it; %.2f ns/weak classifier without them\n", integrals7,
                (ours7 - integrals7) * 1e6 / st);
    std::printf("bench: ns_per_weak_classifier_7layer %.3f\n", ours7 * 1e6 / st);
    std::printf("bench: windows_per_second_7layer %.4g\n", win / (ours7 * 1e-3));
  }
  const RawHitSets hits = compareRawHits();
  std::printf("raw accepted windows on the five photos: ours %zu, OpenCV %zu, in one set only %zu (%s)\n", hits.ours,
              hits.opencv, hits.differ, hits.differ == 0 ? "identical sets" : "DIFFERENT");
  std::printf("equal terms: the same cascade (frontalface_default), the same five 640x480 grey images, scale factor\n"
              "1.1, no minimum size, raw candidates (minNeighbors 0: neither groups), one thread each; CPU time\n");
  std::printf("speedup by wall-clock time: %.3f\n", oursWall > 0 ? cvWall / oursWall : 0.0);
  std::printf("bench: raw_hits_opencv %zu\n", hits.opencv);
  std::printf("bench: raw_hits_differ %zu\n", hits.differ);
  std::printf("bench: detect_speedup_vs_opencv %.3f\n", ours > 0 ? cv / ours : 0.0);
  return hits.differ == 0 && hits.opencv > 0 ? 0 : 1;
}
