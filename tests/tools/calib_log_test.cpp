// SPDX-License-Identifier: Apache-2.0
// Calibration input from a sensor log (fusedet calibrate --log): a synthesised log of a procedural
// scene, whose rig (SynthRig) is known here independently of the log's metadata, replayed into
// calibration frames; targetless calibration from perturbed starts must come back to the rig.

#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>

#include "fusedet/drivers/log/recorder.h"
#include "fusedet/fusion/synthesis/synth_log.h"
#include "fusedet/sensor_logs/calib_log.h"

namespace fusedet::sensor_logs {
namespace {

namespace fs = std::filesystem;

fs::path testDir() {
  const fs::path dir = fs::path(FUSEDET_BINARY_DIR) / "calib_log_test" / std::to_string(::getpid());
  fs::create_directories(dir);
  return dir;
}

// Six strokes of the procedural scene (ground, boxes, wall: it renders its own camera image).
struct SynthesisedLog {
  fs::path path;
  fusion::SynthReport report;  // the rig as the synthesiser used it, not as read back from the log
  ~SynthesisedLog() {
    std::error_code ec;
    fs::remove_all(path.parent_path(), ec);  // ~10 MB per run
  }
};

const SynthesisedLog& proceduralLog() {
  static const SynthesisedLog log = [] {
    fusion::SynthOptions o;
    o.frames = 6;
    SynthesisedLog l;
    l.path = testDir() / "procedural.mcap";
    l.report = fusion::synthesizeLog(o, l.path);
    return l;
  }();
  return log;
}

TEST(CalibLog, FramesAndRigComeFromTheLog) {
  const LogCalibrationInput in = loadLogCalibrationInput(proceduralLog().path, 4);
  const fusion::SynthRig& rig = proceduralLog().report.rig;
  EXPECT_EQ(in.sweeps, 6u);
  EXPECT_EQ(in.paired, 6u);
  ASSERT_EQ(in.frames.size(), 4u) << "4 of the 6 pairs, spread over the log";
  EXPECT_EQ(in.frames.front().name, "sweep-0");
  EXPECT_EQ(in.frames.back().name, "sweep-5");
  for (const fusion::CalibFrame& f : in.frames) {
    EXPECT_EQ(f.image.cols, rig.camera.width);
    EXPECT_EQ(f.image.rows, rig.camera.height);
    EXPECT_EQ(f.image.type(), CV_8UC3);
    EXPECT_GT(f.sweep.points.size(), 5000u) << f.name;
  }
  EXPECT_LT((in.K - rig.camera.K).cwiseAbs().maxCoeff(), 1e-6);
  EXPECT_LT(fusion::rotationErrorDeg(in.laserToCamera, rig.laserToCamera), 1e-6);
  EXPECT_LT(fusion::translationError(in.laserToCamera, rig.laserToCamera), 1e-6);
}

TEST(CalibLog, RejectsLogsItCannotUse) {
  const fs::path dir = testDir();
  const fs::path garbage = dir / "garbage.mcap";
  std::ofstream(garbage) << "not an MCAP file at all";
  EXPECT_ANY_THROW((void)loadLogCalibrationInput(garbage, 4));
  EXPECT_ANY_THROW((void)loadLogCalibrationInput(dir / "missing.mcap", 4));
  const fs::path noRig = dir / "no-rig.mcap";
  {
    drivers::logs::Recorder rec(noRig, {}, std::chrono::milliseconds(0));
    rec.close();
  }
  try {
    (void)loadLogCalibrationInput(noRig, 4);
    FAIL() << "a log without rig metadata was accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("no rig"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)loadLogCalibrationInput(proceduralLog().path, 0), std::invalid_argument);
}

// Starts 1 deg (random axis) and 5 cm (random direction) off the rig, seeded; both measures, coarse
// to fine over 3 levels. The synthetic LMS 291 samples every 1 deg along its scan lines (12 px in
// this camera), so depth edges come from across the scan lines only and translation is weakly
// observed: measured 0.17 / 0.17 / 0.53 deg and 3.5 / 1.9 / 7.6 cm (edges alone: 0.22 / 0.52 /
// 0.67 deg, 2.9 / 7.5 / 28 cm; mutual information alone 0.74-1.13 deg, 14-18 cm).
TEST(CalibLog, TargetlessCalibrationFromAPerturbedStartReturnsToTheRig) {
  const LogCalibrationInput in = loadLogCalibrationInput(proceduralLog().path, 6);
  const Eigen::Isometry3d truth = proceduralLog().report.rig.laserToCamera;
  std::mt19937 rng(5);
  std::normal_distribution<double> gauss;
  fusion::TargetlessOptions opt;
  opt.measure = fusion::AlignmentMeasure::kBoth;
  opt.pyramidLevels = 3;
  opt.estimateUncertainty = false;
  std::vector<double> degs, ms;
  for (int trial = 0; trial < 3; ++trial) {
    Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
    d.linear() = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized()).toRotationMatrix();
    d.translation() = 0.05 * Eigen::Vector3d(gauss(rng), gauss(rng), gauss(rng)).normalized();
    const Eigen::Isometry3d start = d * truth;
    const fusion::TargetlessResult r = fusion::calibrateTargetless(in.frames, in.K, start, opt);
    degs.push_back(fusion::rotationErrorDeg(r.laserToCamera, truth));
    ms.push_back(fusion::translationError(r.laserToCamera, truth));
    std::printf("trial %d: start %.3f deg %.3f m -> %.3f deg %.3f m (edge alignment %.4f -> %.4f, MI %.4f -> %.4f)\n",
                trial, fusion::rotationErrorDeg(start, truth), fusion::translationError(start, truth), degs.back(),
                ms.back(), r.before.edgeAlignment, r.after.edgeAlignment, r.before.mutualInformation,
                r.after.mutualInformation);
    EXPECT_LT(degs.back(), 0.7) << "trial " << trial << ": rotation error must shrink from 1 deg";
    EXPECT_LT(ms.back(), 0.10) << "trial " << trial;
  }
  std::sort(degs.begin(), degs.end());
  std::sort(ms.begin(), ms.end());
  EXPECT_LE(degs[1], 0.3) << "median rotation error";
  EXPECT_LE(ms[1], 0.05) << "median translation error";
}

// Held axes (`fusedet calibrate --hold`) stay exactly where the start has them, about the camera's
// axes as poseDifference measures them, while the others move; their 1-sigma is 0 and they are never
// called uncertain. A rotation about y and a shift along x make the start wrong on free axes too.
TEST(CalibLog, HeldAxesStayAtTheStartAndAreNeverUncertain) {
  const LogCalibrationInput in = loadLogCalibrationInput(proceduralLog().path, 6);
  const Eigen::Isometry3d truth = proceduralLog().report.rig.laserToCamera;
  Eigen::Isometry3d d = Eigen::Isometry3d::Identity();
  d.linear() = Eigen::AngleAxisd(M_PI / 180.0, Eigen::Vector3d::UnitY()).toRotationMatrix();
  d.translation() = Eigen::Vector3d(0.04, 0.0, 0.0);
  const Eigen::Isometry3d start = d * truth;
  fusion::TargetlessOptions opt;
  opt.measure = fusion::AlignmentMeasure::kBoth;
  opt.pyramidLevels = 2;
  opt.hold = fusion::parseCalibAxes({"rz", "ty", "tz"});
  EXPECT_EQ(fusion::calibAxisList(opt.hold, ","), "rz,ty,tz");
  const fusion::TargetlessResult r = fusion::calibrateTargetless(in.frames, in.K, start, opt);
  const Eigen::Matrix<double, 6, 1> moved = fusion::poseDifference(r.laserToCamera, start);
  const Eigen::Matrix<double, 6, 1> sigma = fusion::sigmaPerAxis(r);
  for (int a : {2, 4, 5}) {
    EXPECT_NEAR(moved(a), 0.0, 1e-9) << fusion::calibAxisName(a) << " is held";
    EXPECT_EQ(sigma(a), 0.0) << fusion::calibAxisName(a);
  }
  EXPECT_GT(moved.head<2>().norm() + moved.segment<1>(3).norm(), 1e-4) << "the free axes moved";
  const fusion::CalibAxes uncertain = fusion::uncertainAxes(r, opt.hold, 1e-9, 1e-9);
  for (int a = 0; a < 6; ++a)
    EXPECT_EQ(uncertain[static_cast<std::size_t>(a)], !opt.hold[static_cast<std::size_t>(a)]) << fusion::calibAxisName(a);
  EXPECT_THROW(fusion::parseCalibAxes({"tx", "yaw"}), std::invalid_argument);
  EXPECT_THROW(fusion::parseCalibAxes({"tx,ty"}), std::invalid_argument) << "the command line splits lists, not the library";
  opt.hold = fusion::parseCalibAxes({"rx", "ry", "rz", "tx", "ty", "tz"});
  EXPECT_EQ(fusion::calibAxisList(opt.hold, " "), "rx ry rz tx ty tz");
  EXPECT_EQ(fusion::calibAxisList(fusion::CalibAxes{}, " "), "");
  EXPECT_THROW(fusion::calibrateTargetless(in.frames, in.K, start, opt), std::invalid_argument) << "nothing left to search";
}

}  // namespace
}  // namespace fusedet::sensor_logs
