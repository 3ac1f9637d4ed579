// SPDX-License-Identifier: Apache-2.0
// MultiDetector (all classes in one pass: shared interleaved integrals, breadth-first AVX2 scanner,
// threads) against each class's own Detector on per-class integrals with the one-window scalar
// scanner (Detector::scan(IntegralStack), the path detection took before), on real KITTI stacks
// fused from ../shared/data with the bundled models: the same hits, scores, order and work.

#include "fusedet/boost/class_detection.h"
#include "fusedet/boost/multi_detector.h"

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <opencv2/core.hpp>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <cstdio>
#include <limits>
#include <set>
#include <thread>
#include <tuple>

#include "fusedet/boost/model_io.h"
#include "fusedet/boost/integral_grids.h"
#include "fusedet/boost/integral_stack.h"
#include "fusedet/boost/opencv_cascade.h"
#include "fusedet/boost/vector_path.h"
#include "fusedet/boost/window_scanner.h"
#include "fusedet/core/hue_distance.h"
#include "fusedet/fusion/datasets/kitti.h"

using namespace fusedet;
using namespace fusedet::boosting;
namespace fs = std::filesystem;

namespace {

const fs::path kData = FUSEDET_DATA_DIR;
const fs::path kModels = fs::path(FUSEDET_SOURCE_DIR) / "models";

std::vector<Cascade> bundledModels() {
  std::vector<Cascade> out;
  for (const char* name : {"car.json", "person.json", "bike.json"}) out.push_back(loadModel(kModels / name));
  return out;
}

// Real fused stacks: the first frame and one of the last third of both shared drives.
const std::vector<LayerStack>& kittiStacks() {
  static const std::vector<LayerStack> stacks = [] {
    std::vector<LayerStack> out;
    for (const char* drive : {"kitti", "kitti_0009"}) {
      const fs::path root = kData / drive;
      const std::vector<std::string> ids = fusion::listKittiFrames(root);
      for (const std::string& id : {ids.front(), ids[ids.size() * 2 / 3]}) {
        const fusion::KittiFrame f = fusion::readKittiFrame(root, id);
        out.push_back(fusion::kittiFuser(f.calib, f.image.cols, f.image.rows).fuse(f.image, f.points));
        out.back().source = std::string(drive) + "/" + id;
      }
    }
    return out;
  }();
  return stacks;
}

// The per-class path: each model on its own integrals, one window at a time.
std::vector<RawHit> perClass(const Cascade& c, const LayerStack& s, const ScanParams& p, ScanStats& stats) {
  return Detector(c).scan(integrateFor(c, s), p, &stats);
}

void expectSameHits(const std::vector<RawHit>& got, const std::vector<RawHit>& want, const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  for (std::size_t i = 0; i < got.size(); ++i) {
    EXPECT_EQ(got[i].box, want[i].box) << what << " hit " << i;
    EXPECT_EQ(got[i].score, want[i].score) << what << " hit " << i;  // bit-identical stage sums
    EXPECT_EQ(got[i].scale, want[i].scale) << what << " hit " << i;
  }
}

}  // namespace

TEST(MultiDetector, AllClassesInOnePassDecideAsEachClassAloneOnRealKittiStacks) {
  const std::vector<Cascade> models = bundledModels();
  const MultiDetector all(models);
  ScanParams p;
  p.scaleFactor = 1.1;
  p.step = 2;
  std::size_t referenceHits = 0, windows = 0;
  for (const LayerStack& s : kittiStacks()) {
    p.threads = 1;
    std::vector<ScanStats> oneStats;
    const auto one = all.scan(s, p, &oneStats);
    p.threads = 2;
    const auto two = all.scan(s, p);
    ASSERT_EQ(one.size(), models.size());
    for (std::size_t i = 0; i < models.size(); ++i) {
      ScanStats ref;
      const std::vector<RawHit> want = perClass(models[i], s, p, ref);
      const std::string what = models[i].className + " on " + s.source;
      expectSameHits(one[i], want, what + " (1 thread)");
      expectSameHits(two[i], want, what + " (2 threads)");
      EXPECT_EQ(oneStats[i].windows, ref.windows) << what;
      EXPECT_EQ(oneStats[i].stumps, ref.stumps) << what;
      EXPECT_EQ(oneStats[i].scales, ref.scales) << what;
      referenceHits += want.size();
      windows += ref.windows;
    }
  }
  std::printf("multi-class: %zu windows, %zu raw hits on %zu stacks, identical\n", windows, referenceHits,
              kittiStacks().size());
  EXPECT_GT(windows, 1000000u);
  EXPECT_GT(referenceHits, 20u) << "the bundled models should accept some windows on these frames";
}

namespace {

// The scalar form's hits on `s` (its stats in `stats`) against every vector form's, quick decisions
// on and off: same hits, scores and stump counts.
void expectVectorFormsEqualScalarForm(const MultiDetector& all, const LayerStack& s, std::vector<ScanStats>& stats) {
  ScanParams p;
  p.threads = 1;
  setVectorScanEnabled(false);
  const auto scalar = all.scan(s, p, &stats);
  setVectorScanEnabled(true);
  for (bool quick : {true, false}) {
    setQuickStumpDecisions(quick);
    for (int lanes : {8, 4}) {
      setVectorLanesLimit(lanes);
      // The path that runs: this one where the CPU has it, else the CPU's widest below it.
      EXPECT_EQ(dispatchedVectorLanes(), std::min(lanes, cpuVectorLanes() >= 4 ? cpuVectorLanes() : 1));
      std::vector<ScanStats> b;
      const auto vec = all.scan(s, p, &b);
      for (std::size_t i = 0; i < all.size(); ++i) {
        expectSameHits(vec[i], scalar[i],
                       all.cascade(i).className + " " + std::to_string(lanes) + " lanes, quick " + std::to_string(quick));
        EXPECT_EQ(stats[i].stumps, b[i].stumps) << all.cascade(i).className;
      }
    }
  }
  setQuickStumpDecisions(true);
  setVectorLanesLimit(8);
}

}  // namespace

// The one-window scalar form of the new scanner decides the same as its vector forms (eight lanes
// with AVX-512, four with AVX2; each where the CPU has it, else the next narrower one), with quick
// stump decisions (products, exact fallback near the threshold) and with every stump on the
// exact fallback.
TEST(MultiDetector, ScalarFormEqualsVectorForms) {
  const MultiDetector all(bundledModels());
  for (const LayerStack& s : {kittiStacks().front(), kittiStacks().back()}) {
    std::vector<ScanStats> stats;
    expectVectorFormsEqualScalarForm(all, s, stats);
  }
}

// The vector forms decide a stage before its last stump once no stump to come can change it
// (window_scanner.cpp, setEarlyBounds()). Leaves of +-j for the j-th stump of a stage (exact sums,
// each stump its own weight) and stage thresholds on sums the windows reach make many stage sums
// land exactly on the threshold or one stump away from deciding it: still every hit and score as
// the scalar form, which adds every stump.
TEST(MultiDetector, ScalarFormEqualsVectorFormsWhereStageSumsTieTheThreshold) {
  std::vector<Cascade> models = bundledModels();
  for (Cascade& c : models)
    for (Stage& st : c.stages) {
      double leaves = 0, weights = 0;
      for (std::size_t j = 0; j < st.stumps.size(); ++j) {
        Stump& t = st.stumps[j];
        leaves += std::abs(t.left) + std::abs(t.right);
        const double w = double(j + 1), side = t.left < t.right ? -w : w;
        weights += 2 * w;
        t.left = side;
        t.right = -side;
      }
      // Every sum of +-1, +-2, ..., +-n has the parity of 1 + 2 + ... + n: the threshold takes it,
      // near the model's own.
      const double n = double(st.stumps.size()), t = std::round(st.threshold * weights / leaves);
      st.threshold = std::fmod(std::abs(t - n * (n + 1) / 2), 2.0) == 0 ? t : t + 1;
    }
  const MultiDetector all(models);
  ScanParams p;
  p.threads = 1;
  const LayerStack& s = kittiStacks().front();
  setVectorScanEnabled(false);
  const auto scalar = all.scan(s, p);
  setVectorScanEnabled(true);
  std::size_t hits = 0;
  for (int lanes : {8, 4}) {
    setVectorLanesLimit(lanes);
    const auto vec = all.scan(s, p);
    for (std::size_t i = 0; i < all.size(); ++i) {
      expectSameHits(vec[i], scalar[i], all.cascade(i).className + " " + std::to_string(lanes) + " lanes");
      hits += scalar[i].size();
    }
  }
  setVectorLanesLimit(8);
  EXPECT_GT(hits, 0u) << "thresholds on reachable sums should let some windows through";
}

// Stage 0 runs stump by stump over a row's steps, one loop per stump shape, table type and corner
// load (vector_stages.inc, rowStageSums()); the bundled models' first stages read only the laser
// layers with a few shapes. Here each model's stage 0 also takes the first stump of every (feature
// type, layer) pair of the whole cascade, so stage 0 reads camera (int32) and laser or hue
// (double) tables with every shape at every scale's loads, mixed loads in one stage included:
// still every hit, score and stump count as the scalar form.
TEST(MultiDetector, ScalarFormEqualsVectorFormsWithEveryShapeAndTableInStageZero) {
  const LayerStack& s = kittiStacks().back();
  std::vector<Cascade> models = bundledModels();
  std::vector<std::size_t> firstSize;
  std::set<FeatureType> types;
  std::set<bool> eightBit;  // the stage-0 layers' kinds: 8-bit (int32 tables) or not (double)
  for (Cascade& c : models) {
    std::set<std::pair<FeatureType, int>> seen;
    for (const Stump& t : c.stages.front().stumps)
      seen.insert({c.features[static_cast<std::size_t>(t.feature)].type, c.features[static_cast<std::size_t>(t.feature)].layer});
    std::vector<Stump> added;
    for (std::size_t st = 1; st < c.stages.size(); ++st)
      for (const Stump& t : c.stages[st].stumps) {
        const Feature& f = c.features[static_cast<std::size_t>(t.feature)];
        if (seen.insert({f.type, f.layer}).second) added.push_back(t);
      }
    auto& first = c.stages.front().stumps;
    first.insert(first.end(), added.begin(), added.end());
    firstSize.push_back(first.size());
    for (const Stump& t : first) {
      const Feature& f = c.features[static_cast<std::size_t>(t.feature)];
      types.insert(f.type);
      const auto* layer = s.find(c.layers[static_cast<std::size_t>(f.layer)]);  // none: hue_distance, made per class
      eightBit.insert(layer && layer->data.depth() == CV_8U);
    }
  }
  ASSERT_EQ(types.size(), kFeatureTypeCount) << "stage 0 should hold every feature type";
  ASSERT_EQ(eightBit.size(), 2u) << "stage 0 should read int32 and double tables";
  const MultiDetector all(models);
  std::vector<ScanStats> a;
  expectVectorFormsEqualScalarForm(all, s, a);
  for (std::size_t i = 0; i < all.size(); ++i) {  // stage 0 passes some windows and rejects others
    const std::size_t second = models[i].stages[1].stumps.size();
    EXPECT_GT(a[i].stumps, a[i].windows * firstSize[i]) << models[i].className;
    EXPECT_LT(a[i].stumps, a[i].windows * (firstSize[i] + second)) << models[i].className;
  }
}

// Layers whose values are NaN, infinite or huge in places: the vector forms' quick decisions (bounded
// by each layer's largest magnitude, IntegralGrids::bounds) and their exact fallback still decide
// as the scalar form, window for window.
TEST(MultiDetector, ScalarFormEqualsVectorFormsOnNonFiniteAndHugeValues) {
  const MultiDetector all(bundledModels());
  ScanParams p;
  p.threads = 1;
  LayerStack s = kittiStacks().front();  // its layers' pixels are shared: the two changed are copies
  cv::Mat& distance = s.find(layer::kDistance)->data;
  cv::Mat& remission = s.find(layer::kRemission)->data;
  distance = distance.clone();
  remission = remission.clone();
  ASSERT_EQ(distance.type(), CV_32FC1);
  const int w = distance.cols, h = distance.rows;
  distance(cv::Rect(w / 8, h / 4, w / 10, h / 3)).setTo(std::numeric_limits<float>::quiet_NaN());
  distance(cv::Rect(w / 2, h / 2, w / 12, h / 4)).setTo(std::numeric_limits<float>::infinity());
  cv::Mat huge = remission(cv::Rect(remission.cols / 3, 0, remission.cols / 6, remission.rows / 2));
  huge.convertTo(huge, -1, 1e30);
  std::vector<ScanStats> a;
  setVectorScanEnabled(false);
  const auto scalar = all.scan(s, p, &a);
  setVectorScanEnabled(true);
  for (int lanes : {8, 4}) {
    setVectorLanesLimit(lanes);
    std::vector<ScanStats> b;
    const auto vec = all.scan(s, p, &b);
    for (std::size_t i = 0; i < all.size(); ++i) {
      expectSameHits(vec[i], scalar[i], all.cascade(i).className + " " + std::to_string(lanes) + " lanes");
      EXPECT_EQ(a[i].stumps, b[i].stumps);
    }
  }
  setVectorLanesLimit(8);
}

// IntegralGrids::bounds, which the quick decisions rest on: each layer's largest |value| (NaN when
// a value is NaN), 255 for 8-bit layers in int32 tables, the derived hue_distance's own.
TEST(IntegralGrids, BoundsAreEachLayersLargestMagnitude) {
  LayerStack s(64, 48);
  cv::Mat f(48, 64, CV_32FC1), u16(48, 64, CV_16UC1), hue(48, 64, CV_32FC1), u8(48, 64, CV_8UC1, cv::Scalar(7));
  cv::randu(f, -50.f, 20.f);
  f.at<float>(30, 9) = -77.5f;
  cv::randu(u16, 0, 4000);
  u16.at<std::uint16_t>(3, 3) = 60000;
  cv::randu(hue, 0.f, 359.f);
  s.set(Layer{"distance", f, {}});
  s.set(Layer{"remission", u16, {}});
  s.set(Layer{"hue", hue, {}});
  s.set(Layer{"red", u8, {}});
  const IntegralGrids grids(s, {{"distance", {}}, {"remission", {}}, {"hue_distance", 215.0}, {"red", {}}}, 1);
  auto bound = [&](const LayerRequest& r) {
    const SlotRef ref = grids.find(r);
    return grids.grids()[static_cast<std::size_t>(ref.grid)].bounds[static_cast<std::size_t>(ref.slot)];
  };
  EXPECT_EQ(bound({"distance", {}}), 77.5);
  EXPECT_EQ(bound({"remission", {}}), 60000.0);
  EXPECT_EQ(bound({"hue_distance", 215.0}), cv::norm(hueDistanceLayer(hue, 215.0), cv::NORM_INF));
  EXPECT_EQ(bound({"red", {}}), 255.0);
  f.at<float>(40, 60) = std::numeric_limits<float>::quiet_NaN();
  const IntegralGrids withNan(s, {{"distance", {}}}, 1);
  EXPECT_TRUE(std::isnan(withNan.grids().front().bounds.front()));
}

// The tables hold integrateLayer()'s values, bit for bit: two 8-bit layers (int32 tables, widths
// with and without a remainder of four columns) and a float layer of another grid, on stacks of
// two sizes one after the other and the first again (the tables' buffers are reused between them).
TEST(IntegralGrids, TablesEqualIntegrateLayerOnStacksOfOtherSizes) {
  auto stackOf = [](int w, int h, int seed) {
    cv::setRNGSeed(seed);
    LayerStack s(w, h);
    cv::Mat red(h, w, CV_8UC1), green(h, w, CV_8UC1), distance(h / 2, w / 2 + 1, CV_32FC1);
    cv::randu(red, 0, 256);
    cv::randu(green, 0, 256);
    red.at<std::uint8_t>(h - 1, w - 1) = 255;
    cv::randu(distance, -30.f, 80.f);
    s.set(Layer{"red", red, {}});
    s.set(Layer{"green", green, {}});
    s.set(Layer{"distance", distance, {}});
    return s;
  };
  const std::vector<LayerRequest> requests{{"red", {}}, {"green", {}}, {"distance", {}}};
  for (const auto& [w, h, seed] : {std::tuple{67, 41, 1}, std::tuple{128, 96, 2}, std::tuple{67, 41, 3}}) {
    const LayerStack s = stackOf(w, h, seed);
    const IntegralGrids grids(s, requests, 1);
    for (const LayerRequest& r : requests) {
      const SlotRef ref = grids.find(r);
      const IntegralGrid& g = grids.grids()[static_cast<std::size_t>(ref.grid)];
      const LayerIntegral want = integrateLayer(r.name, s.at(r.name).data);
      ASSERT_EQ(g.width, want.width);
      ASSERT_EQ(g.height, want.height);
      EXPECT_EQ(g.exactInt, r.name != "distance");
      std::size_t differ = 0;
      for (int y = 0; y <= g.height; ++y)
        for (int x = 0; x <= g.width; ++x) {
          const std::ptrdiff_t at = y * g.pitch + ref.slot * g.stride + x;
          const double have = g.exactInt ? double(g.idata[static_cast<std::size_t>(at)]) : g.data[static_cast<std::size_t>(at)];
          differ += have == want.sum[static_cast<std::size_t>(y * want.stride() + x)] ? 0 : 1;
        }
      EXPECT_EQ(differ, 0u) << r.name << " on the " << w << "x" << h << " stack";
    }
  }
}

// The optimised scanner (one pass, widest vector path, quick stump decisions, branch-free survivor
// lists; 1 and 2 threads) against the plain definition: evaluateWindow() - one window, per-layer
// integrals, featureValue() per stump - on every window of every scale, enumerated here from the
// documented rule (sizes from the base window by the scale factor at the model's aspect ratio,
// position step = step x scale, both rounded half up), on the demo's KITTI stack with the bundled
// models. Same accepted windows, same scores (bit for bit), same number of windows.
namespace {

// The documented scan windows of `c` on `s` (sizes from the base window by the scale factor at the
// model's aspect ratio, position step = step x scale, both rounded half up), each evaluated alone
// with evaluateWindow() on per-layer integrals: fn(box, result).
template <class Fn>
void forEachDocumentedWindow(const Cascade& c, const LayerStack& s, const ScanParams& p, Fn&& fn) {
  auto half = [](double v) { return static_cast<int>(std::floor(v + 0.5)); };
  const IntegralStack in = integrateFor(c, s);
  for (double scale = 1.0;; scale *= p.scaleFactor) {
    const int w = half(c.windowWidth * scale), h = half(c.windowHeight * scale);
    if (w > s.width() || h > s.height()) break;
    const int step = std::max(1, half(p.step * scale));
    for (int y = 0; y + h <= s.height(); y += step)
      for (int x = 0; x + w <= s.width(); x += step) {
        const Box box{double(x), double(y), double(w), double(h)};
        fn(box, evaluateWindow(c, in, box));
      }
  }
}

void expectOptimisedScanEqualsPlainPerWindowEvaluation(const std::vector<Cascade>& models, const char* kind) {
  const MultiDetector all(models);
  const fs::path root = kData / "kitti";
  const std::vector<std::string> ids = fusion::listKittiFrames(root);
  const std::string id = ids[std::min(ids.size() - 1, static_cast<std::size_t>(ids.size() * 2.0 / 3.0 + 0.5))];
  const fusion::KittiFrame f = fusion::readKittiFrame(root, id);
  const LayerStack s = fusion::kittiFuser(f.calib, f.image.cols, f.image.rows).fuse(f.image, f.points);
  ScanParams p;
  p.scaleFactor = 1.1;
  p.step = 2;
  std::size_t accepted = 0, windows = 0, deep = 0;
  std::vector<std::vector<RawHit>> want(models.size());
  std::vector<std::size_t> count(models.size(), 0);
  for (std::size_t i = 0; i < models.size(); ++i) {
    const Cascade& c = models[i];
    forEachDocumentedWindow(c, s, p, [&](const Box& box, const WindowResult& r) {
      ++count[i];
      if (r.stagesPassed >= 3) ++deep;
      if (r.accepted) want[i].push_back(RawHit{box, r.score, 0});
    });
    accepted += want[i].size();
    windows += count[i];
  }
  for (int threads : {1, 2}) {
    p.threads = threads;
    std::vector<ScanStats> stats;
    const auto got = all.scan(s, p, &stats);
    for (std::size_t i = 0; i < models.size(); ++i) {
      const std::string what = models[i].className + ", " + std::to_string(threads) + " threads";
      EXPECT_EQ(stats[i].windows, count[i]) << what;
      ASSERT_EQ(got[i].size(), want[i].size()) << what;
      for (std::size_t k = 0; k < want[i].size(); ++k) {  // both in (scale, row, column) order
        EXPECT_EQ(got[i][k].box, want[i][k].box) << what << " hit " << k;
        EXPECT_EQ(got[i][k].score, want[i][k].score) << what << " hit " << k;
      }
    }
  }
  std::printf("%s: plain per-window evaluation: %zu windows (%zu past 3 stages), %zu accepted; optimised scan identical\n",
              kind, windows, deep, accepted);
  EXPECT_GT(accepted, 100u) << "the comparison needs accepted windows";
  EXPECT_GT(deep, 10000u) << "and windows that go deep into the cascades";
}

}  // namespace

TEST(MultiDetector, OptimisedScanEqualsPlainPerWindowEvaluation) {
  expectOptimisedScanEqualsPlainPerWindowEvaluation(bundledModels(), "bundled models");
}

// Each class's hue_distance is its own: models with different reference hues in one pass.
TEST(MultiDetector, EachClassUsesItsOwnReferenceHue) {
  std::vector<Cascade> models = bundledModels();
  models[1].referenceHue = 30;
  models[2].referenceHue = 120;
  const MultiDetector all(models);
  ScanParams p;
  p.threads = 2;
  p.scaleFactor = 1.25;
  const LayerStack& s = kittiStacks().back();
  const auto hits = all.scan(s, p);
  for (std::size_t i = 0; i < models.size(); ++i) {
    ScanStats ref;
    expectSameHits(hits[i], perClass(models[i], s, p, ref), models[i].className);
  }
}

TEST(MultiDetector, OpenCvModelsRunBesideOursAsAlone) {
  std::vector<Cascade> models = bundledModels();
  models.insert(models.begin() + 1,
                loadOpenCvCascade("/usr/share/opencv4/haarcascades/haarcascade_frontalface_default.xml"));
  const MultiDetector all(models);
  ScanParams p;
  p.threads = 2;
  p.scaleFactor = 1.2;
  const LayerStack& s = kittiStacks().front();
  const auto hits = all.scan(s, p);
  ASSERT_EQ(hits.size(), models.size());
  for (std::size_t i = 0; i < models.size(); ++i)
    expectSameHits(hits[i], Detector(models[i]).scan(s, p), models[i].className);
}

TEST(MultiDetector, GroupsEachClassUnderItsName) {
  const MultiDetector all(bundledModels());
  ScanParams p;
  p.threads = 2;
  GroupParams g;
  g.minNeighbors = 1;
  for (const LayerStack& s : kittiStacks()) {
    const std::vector<Detection> d = detect(all, s, p, g);
    std::vector<Detection> want;
    for (std::size_t i = 0; i < all.size(); ++i) {
      const auto one = detect(Detector(all.cascade(i)), s, p, g);
      want.insert(want.end(), one.begin(), one.end());
    }
    ASSERT_EQ(d.size(), want.size());
    for (std::size_t i = 0; i < d.size(); ++i) {
      EXPECT_EQ(d[i].className, want[i].className);
      EXPECT_EQ(d[i].box, want[i].box);
      EXPECT_EQ(d[i].score, want[i].score);
    }
  }
}

// detectPerClass(): each class grouped and box-refined with its own settings, the others with the
// general ones - against each class's own Detector, grouped and refined here.
TEST(MultiDetector, DetectPerClassUsesEachClassesOwnGroupingAndLaserExtent) {
  const MultiDetector all(bundledModels());
  ScanParams p;
  p.threads = 2;
  GroupParams g;  // general: 3 neighbours
  LaserExtentParams off;
  LaserExtentParams on;
  on.enabled = true;
  const std::vector<ClassGrouping> own{{"car", 1, true}};
  std::size_t refined = 0, carDetections = 0;
  for (const LayerStack& s : kittiStacks()) {
    // Nothing per class: the general rule for every model.
    const std::vector<Detection> plain = detectPerClass(all, s, p, g, off, {});
    const std::vector<Detection> general = detect(all, s, p, g);
    ASSERT_EQ(plain.size(), general.size());
    for (std::size_t i = 0; i < plain.size(); ++i) EXPECT_EQ(plain[i].box, general[i].box);

    const std::vector<Detection> d = detectPerClass(all, s, p, g, off, own);
    std::vector<Detection> want;
    for (std::size_t i = 0; i < all.size(); ++i) {
      const bool car = all.cascade(i).className == "car";
      GroupParams gi = g;
      if (car) gi.minNeighbors = 1;
      std::vector<Detection> one = detect(Detector(all.cascade(i)), s, p, gi);
      if (car) {
        const std::vector<Detection> before = one;
        refineToLaserExtent(one, s, on);
        for (std::size_t k = 0; k < one.size(); ++k) refined += one[k].box == before[k].box ? 0 : 1;
        carDetections += one.size();
      }
      want.insert(want.end(), one.begin(), one.end());
    }
    ASSERT_EQ(d.size(), want.size()) << s.source;
    for (std::size_t i = 0; i < d.size(); ++i) {
      EXPECT_EQ(d[i].className, want[i].className);
      EXPECT_EQ(d[i].box, want[i].box) << s.source << " detection " << i;
      EXPECT_EQ(d[i].score, want[i].score);
    }
  }
  // Not vacuous: car's single-window groups exist and the laser moved some of their edges.
  EXPECT_GT(carDetections, 0u);
  EXPECT_GT(refined, 0u);
}

// classGroupings() / classDetectionSetup(): the one rule "which settings does a class get" that
// fusedetd's built-in detection.classes, experiments, demo and detect use. Expected values are
// classDetectionDefault()'s and the general settings given here.
TEST(ClassDetection, GroupingsComeFromTheClassDefaultsUnlessSetForEveryClass) {
  const std::optional<ClassDetection> car = classDetectionDefault("car");
  ASSERT_TRUE(car.has_value());
  EXPECT_EQ(classesWithOwnDetection(), std::vector<std::string>{"car"});
  // Only classes with settings of their own get an entry, each once.
  const std::vector<ClassGrouping> k = classGroupings({"person", "car", "bike", "car"});
  ASSERT_EQ(k.size(), 1u);
  EXPECT_EQ(k[0].className, "car");
  EXPECT_EQ(k[0].minNeighbors, car->minNeighbors);
  EXPECT_EQ(k[0].laserExtent, car->laserExtent);
  EXPECT_TRUE(classGroupings({"person", "bike", "cars"}).empty());
  // Of a MultiDetector: its models' classes (bundled: car, person, bike).
  const std::vector<ClassGrouping> m = classGroupings(MultiDetector(bundledModels()));
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].minNeighbors, car->minNeighbors);
  // A setting given for every class replaces car's own; the other stays car's.
  GroupParams five;
  five.minNeighbors = 5;
  LaserExtentParams off;
  const std::vector<ClassGrouping> g = classGroupings({"car"}, five, off, SetForEveryClass{false, false, true, false});
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].minNeighbors, 5);
  EXPECT_EQ(g[0].laserExtent, car->laserExtent);
  const std::vector<ClassGrouping> e = classGroupings({"car"}, five, off, SetForEveryClass{false, false, false, true});
  EXPECT_EQ(e.at(0).minNeighbors, car->minNeighbors);
  EXPECT_FALSE(e.at(0).laserExtent);
  // The full setup of a class scanned on its own (experiments): scan too.
  DetectionSetup general;
  general.scan.scaleFactor = 1.2;
  general.scan.step = 3;
  general.group.minNeighbors = 4;
  const DetectionSetup c = classDetectionSetup("car", general);
  EXPECT_EQ(c.scan.scaleFactor, car->scaleFactor);
  EXPECT_EQ(c.scan.step, car->step);
  EXPECT_EQ(c.group.minNeighbors, car->minNeighbors);
  EXPECT_EQ(c.laserExtent.enabled, car->laserExtent);
  const DetectionSetup stepGiven = classDetectionSetup("car", general, SetForEveryClass{false, true, false, false});
  EXPECT_EQ(stepGiven.scan.step, 3);
  EXPECT_EQ(stepGiven.scan.scaleFactor, car->scaleFactor);
  const DetectionSetup person = classDetectionSetup("person", general);
  EXPECT_EQ(person.scan.scaleFactor, 1.2);
  EXPECT_EQ(person.group.minNeighbors, 4);
  EXPECT_FALSE(person.laserExtent.enabled);
}

// groupingFor(): the class's entry replaces only min neighbours and laser extent; a class without
// an entry keeps the general settings.
TEST(ClassDetection, GroupingForTakesTheClassEntryOrTheGeneralSettings) {
  GroupParams general;
  general.minNeighbors = 4;
  general.eps = 0.3;
  LaserExtentParams extent;
  extent.tolerance = 2.0;
  const std::vector<ClassGrouping> perClass{{"car", 16, true}, {"bike", 7, false}};
  const GroupingOfClass car = groupingFor("car", perClass, general, extent);
  EXPECT_TRUE(car.own);
  EXPECT_EQ(car.group.minNeighbors, 16);
  EXPECT_EQ(car.group.eps, 0.3);
  EXPECT_TRUE(car.extent.enabled);
  EXPECT_EQ(car.extent.tolerance, 2.0);
  const GroupingOfClass bike = groupingFor("bike", perClass, general, extent);
  EXPECT_TRUE(bike.own);
  EXPECT_EQ(bike.group.minNeighbors, 7);
  EXPECT_FALSE(bike.extent.enabled);
  const GroupingOfClass person = groupingFor("person", perClass, general, extent);
  EXPECT_FALSE(person.own);
  EXPECT_EQ(person.group.minNeighbors, 4);
  EXPECT_FALSE(person.extent.enabled);
  EXPECT_FALSE(groupingFor("car", {}, general, extent).own);
}

TEST(MultiDetector, MissingLayerIsNamed) {
  const MultiDetector all(bundledModels());
  LayerStack s = kittiStacks().front();
  LayerStack noLaser(s.width(), s.height());
  for (const Layer& l : s.layers())
    if (l.name != "distance") noLaser.set(l);
  try {
    all.scan(noLaser, ScanParams{});
    ADD_FAILURE() << "no error for a stack without distance";
  } catch (const std::out_of_range& e) {
    EXPECT_NE(std::string(e.what()).find("distance"), std::string::npos) << e.what();
  }
}

TEST(MultiDetector, InvalidModelIsRejectedAtConstruction) {
  std::vector<Cascade> models = bundledModels();
  models[2].stages[0].threshold = NAN;
  models[2].source = "bad.json";
  EXPECT_THROW(MultiDetector{models}, std::invalid_argument);
}

namespace {
// Minor page faults of the calling thread while `work` runs: memory it touched for the first time.
template <class Work>
long minorFaults(Work&& work) {
  rusage before{}, after{};
  getrusage(RUSAGE_THREAD, &before);
  work();
  getrusage(RUSAGE_THREAD, &after);
  return after.ru_minflt - before.ru_minflt;
}
}  // namespace

// prepare() leaves the thread its table buffers: the tables of a stack of the same sizes then
// touch no fresh memory, where a thread's first tables fault their pages in. Each case on a new
// thread (the buffers are kept per thread).
TEST(MultiDetector, PrepareLeavesTheThreadTheTablesOfItsFirstStack) {
  const std::vector<Cascade> models = bundledModels();
  const MultiDetector all(models);
  const LayerStack& s = kittiStacks().front();
  std::vector<LayerRequest> requests;
  for (const Cascade& c : models)
    for (LayerRequest& r : layerRequests(c)) requests.push_back(std::move(r));
  ScanParams one;
  one.threads = 1;
  long cold = -1, prepared = -1;
  std::thread([&] { cold = minorFaults([&] { (void)IntegralGrids(s, requests, 1); }); }).join();
  std::thread([&] {
    all.prepare(s, one);
    prepared = minorFaults([&] { (void)IntegralGrids(s, requests, 1); });
  }).join();
  // Megabytes of tables: at least one fault per 2 MiB page even where the kernel gives huge pages.
  EXPECT_GE(cold, 4) << "a thread's first tables touched no fresh memory?";
  EXPECT_LE(prepared * 4, cold) << "after prepare(): " << prepared << " faults, a thread's first tables: " << cold;
  std::printf("minor page faults of the tables: first on a thread %ld, after prepare() %ld\n", cold, prepared);
}
