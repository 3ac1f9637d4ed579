// MultiDetector (all classes in one pass: shared interleaved integrals, breadth-first AVX2 scanner,
// threads) against each class's own Detector on per-class integrals with the one-window scalar
// scanner (Detector::scan(IntegralStack), the path detection took before), on real KITTI stacks
// fused from ../shared/data with the bundled models: the same hits, scores, order and work.

#include "fusedet/boost/multi_detector.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "fusedet/boost/model_io.h"
#include "fusedet/boost/opencv_cascade.h"
#include "fusedet/fusion/kitti.h"

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

// Real fused stacks: the first frame and one of the held-back third of both shared drives.
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

// The one-window scalar form of the new scanner decides the same as its vector forms (eight lanes
// with AVX-512, four with AVX2; each where the CPU has it, else the next narrower one).
TEST(MultiDetector, ScalarFormEqualsVectorForms) {
  const MultiDetector all(bundledModels());
  ScanParams p;
  p.threads = 1;
  for (const LayerStack& s : {kittiStacks().front(), kittiStacks().back()}) {
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
