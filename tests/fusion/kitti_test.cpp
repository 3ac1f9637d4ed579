// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/kitti.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;
using namespace fusedet::fusion;

namespace {
const fs::path kKitti = fs::path(FUSEDET_DATA_DIR) / "kitti";

fs::path writeTemp(const std::string& name, const std::string& text) {
  const fs::path p = fs::temp_directory_path() / ("fusedet_kitti_test_" + name);
  std::ofstream(p) << text;
  return p;
}
}  // namespace

TEST(Kitti, ReadsARealFrame) {
  const auto ids = listKittiFrames(kKitti);
  ASSERT_EQ(ids.size(), 52u);  // SOURCE.md: every 3rd frame of 154
  EXPECT_EQ(ids.front(), "000000");
  const KittiFrame f = readKittiFrame(kKitti, "000000");
  EXPECT_EQ(f.image.cols, 1242);
  EXPECT_EQ(f.image.rows, 375);
  EXPECT_EQ(f.points.size() * 16, fs::file_size(kKitti / "velodyne" / "000000.bin"));
  EXPECT_GT(f.points.size(), 98'000u);
  // P2 of drive 0005 (calib/000000.txt): fx = 721.5377, cx = 609.5593
  EXPECT_DOUBLE_EQ(f.calib.P2(0, 0), 721.5377);
  EXPECT_DOUBLE_EQ(f.calib.P2(0, 2), 609.5593);
  // label_2/000000.txt: 2 DontCare then a Van at x 296.744956..455.226042
  ASSERT_GE(f.labels.size(), 3u);
  EXPECT_TRUE(f.labels[0].ignore);
  EXPECT_EQ(f.labels[2].sourceClass, "Van");
  EXPECT_NEAR(f.labels[2].box.w, 455.226042 - 296.744956, 1e-9);
}

TEST(Kitti, MapsClasses) {
  const auto p = writeTemp("labels.txt",
                           "Car 0 1 0 10 20 30 60 0 0 0 0 0 0 0\n"
                           "Pedestrian 0 0 0 1 2 3 4 0 0 0 0 0 0 0\n"
                           "Cyclist 0 0 0 1 2 3 4 0 0 0 0 0 0 0\n"
                           "Tram 0 0 0 1 2 3 4 0 0 0 0 0 0 0\n");
  const auto labels = readKittiLabels(p);
  ASSERT_EQ(labels.size(), 4u);
  EXPECT_EQ(labels[0].className, "car");
  EXPECT_EQ(labels[0].occlusion, 1);
  EXPECT_EQ(labels[0].box, (fusedet::Box{10, 20, 20, 40}));
  EXPECT_EQ(labels[1].className, "person");
  EXPECT_EQ(labels[2].className, "bike");
  EXPECT_TRUE(labels[3].ignore);
}

TEST(Kitti, BadFilesNameTheFileAndProblem) {
  const auto calib = writeTemp("calib.txt", "P2: 1 2 3\n");
  try {
    (void)readKittiCalib(calib);
    FAIL();
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(calib.string()), std::string::npos);
    EXPECT_NE(std::string(e.what()).find("P2"), std::string::npos);
  }
  const auto velo = writeTemp("velo.bin", std::string(17, '\0'));
  EXPECT_THROW((void)readKittiVelodyne(velo), std::runtime_error);
  const auto labels = writeTemp("bad_labels.txt", "Car 0 0 x\n");
  EXPECT_THROW((void)readKittiLabels(labels), std::runtime_error);
  EXPECT_THROW((void)readKittiFrame(kKitti, "999999"), std::runtime_error);
}

// Issue 37: every corner below is finite, but right - left (or bottom - top) overflows to inf; the
// label was accepted with an infinite width or height (and an IoU with it is NaN).
TEST(Kitti, LabelBoxesWhoseSizeIsNotFiniteAreRefused) {
  for (const char* line : {"Car 0 0 0 -1e308 20 1e308 60 0 0 0 0 0 0 0", "Car 0 0 0 10 -1.7e308 30 1.7e308 0 0 0 0 0 0 0"}) {
    const auto p = writeTemp("huge_labels.txt", std::string("Car 0 0 0 1 2 3 4 0 0 0 0 0 0 0\n") + line + "\n");
    try {
      (void)readKittiLabels(p);
      ADD_FAILURE() << "accepted: " << line;
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(p.string() + ": line 2: box has a negative or non-finite size"),
                std::string::npos)
          << e.what();
    }
  }
  // Large but finite sizes stay boxes.
  const auto p = writeTemp("large_labels.txt", "Car 0 0 0 -1e300 0 1e300 1e300 0 0 0 0 0 0 0\n");
  const auto labels = readKittiLabels(p);
  ASSERT_EQ(labels.size(), 1u);
  EXPECT_EQ(labels[0].box, (fusedet::Box{-1e300, 0, 2e300, 1e300}));
}

// Found writing the fuzz corpus (issue 37, tests/fuzz/corpus/kitti_text/calib_tiny_focal.txt): a
// P2 with a focal length of 1e-300 passes the K [I | t] form check, and K^-1 P2(:, 3) overflows
// to inf: every projected point would have been inf or NaN. It is refused now; a sane K is not.
TEST(Kitti, ACalibWhoseTransformIsNotFiniteIsRefused) {
  KittiCalib calib;
  calib.P2 << 1e-300, 0, 0, 1e300, 0, 1e-300, 0, 0, 0, 0, 1, 0;
  calib.R0rect.setIdentity();
  calib.TrVeloToCam << 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0;
  try {
    (void)kittiProjection(calib, 1242, 375);
    FAIL() << "accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("non-finite transform"), std::string::npos) << e.what();
  }
  calib.P2 << 700, 0, 600, 45, 0, 700, 180, 0, 0, 0, 1, 0;
  const auto p = kittiProjection(calib, 1242, 375);
  EXPECT_TRUE(p.sweepToCamera.matrix().allFinite());
  EXPECT_NEAR(p.sweepToCamera.translation().x(), 45.0 / 700, 1e-12);
}
