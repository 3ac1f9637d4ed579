// SPDX-License-Identifier: Apache-2.0
// Targetless laser->camera calibration on real KITTI frames (issue 17's acceptance run): start
// from the rig's calib perturbed by a random rotation and translation, refine, and measure how far
// the result is from the calib. Side by side in the same run: the start error (the peer: doing
// nothing) and, with --measures, the agreement measures against each other on the same starts.
// Ends with "bench:" lines; exits 1 if the median error exceeds --max-rotation-deg or
// --max-translation, so the ctest variant can fail.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iterator>
#include <random>
#include <sstream>

#include "calib_starts.h"
#include "fusedet/core/cpu_time.h"
#include "fusedet/fusion/calibration/calib_kitti.h"
#include "fusedet/fusion/calibration/calib_targetless.h"
#include "fusedet/fusion/calibration/score_profile.h"

namespace {

using namespace fusedet::fusion;

double cpuSeconds() { return fusedet::processCpuMs() / 1000.0; }

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const std::size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}


}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Targetless calibration trials on KITTI frames: perturbed starts, errors against the calib."};
  std::vector<std::string> dirs;
  const std::string data = FUSEDET_DATA_DIR;
  dirs = {data + "/kitti", data + "/kitti_0009", data + "/kitti_object_more", data + "/kitti_object_sample"};
  int trials = 10, frames = 10;
  unsigned seed = 17;
  double maxDeg = 2.0, maxT = 0.10, fraction = 0.5;
  double failDeg = 0.3, failT = 0.03;
  std::vector<std::string> measures = {"edges"};
  int levels = 1;
  app.add_option("--kitti", dirs, "KITTI-layout directories (frames of the most common rig are used)")->capture_default_str();
  app.add_option("--trials", trials, "perturbed starts")->capture_default_str();
  app.add_option("--frames", frames, "frames per calibration, spread over the directories")->capture_default_str();
  app.add_option("--seed", seed, "random seed of the perturbations")->capture_default_str();
  app.add_option("--max-deg", maxDeg, "largest start rotation error [deg]")->capture_default_str();
  app.add_option("--max-m", maxT, "largest start translation error [m]")->capture_default_str();
  app.add_option("--min-fraction", fraction, "start errors are drawn from [fraction, 1] x the largest")->capture_default_str();
  app.add_option("--measures", measures, "mi, edges, both: each runs on the same starts")->capture_default_str();
  app.add_option("--levels", levels, "pyramid levels")->capture_default_str();
  app.add_option("--max-rotation-deg", failDeg, "exit 1 if a measure's median rotation error is larger")->capture_default_str();
  app.add_option("--max-translation", failT, "exit 1 if a measure's median translation error [m] is larger")->capture_default_str();
  bool profile = false, occlusion = true, between = true;
  app.add_flag("!--edge-at-sample", between, "depth edges at the foreground sample, not half way to the background one");
  double decay = TargetlessOptions{}.edgeDecay;
  app.add_option("--edge-decay", decay, "max-decay spread of image edges per pixel")->capture_default_str();
  app.add_flag("!--keep-occluded", occlusion, "keep points hidden behind nearer ones in the camera view");
  app.add_flag("--profile", profile, "print the scores along each axis around the calib, then exit");
  CLI11_PARSE(app, argc, argv);

  std::vector<std::filesystem::path> roots(dirs.begin(), dirs.end());
  const KittiCalibrationInput in = loadKittiCalibrationInput(roots, static_cast<std::size_t>(frames));
  std::printf("frames: %zu of %zu of the rig (%zu of other rigs skipped):", in.frames.size(), in.rigFrames, in.otherRigFrames);
  for (const CalibFrame& f : in.frames) std::printf(" %s", f.name.c_str());
  std::printf("\nstarts: calib perturbed by %.2f..%.2f deg and %.3f..%.3f m, seed %u; one thread\n",
              fraction * maxDeg, maxDeg, fraction * maxT, maxT, seed);

  TargetlessOptions base;
  base.edgeDecay = decay;
  base.removeOccluded = occlusion;
  base.edgeBetweenSamples = between;
  if (profile) {
    std::fputs(formatScoreProfile(scoreProfile(in.frames, in.K, in.laserToCamera, 20, 0.05, 0.005, base)).c_str(), stdout);
    // Each frame alone: where its own profiles peak shows whether the frames agree.
    std::printf("\neach frame alone: peaks (rot_x rot_y rot_z [deg], t_x t_y t_z [cm]), edges | mi\n");
    for (const CalibFrame& f : in.frames) {
      const std::string table = formatScoreProfile(scoreProfile({f}, in.K, in.laserToCamera, 20, 0.05, 0.005, base));
      std::printf("%-28s", f.name.c_str());
      for (std::size_t at = table.find("peak at"); at != std::string::npos; at = table.find("peak at", at + 1))
        std::printf(" %s |", table.substr(at + 7, table.find('\n', at) - at - 7).c_str());
      std::printf("\n");
    }
    return 0;
  }
  std::mt19937 rng(seed);
  std::vector<Eigen::Isometry3d> starts;
  for (int t = 0; t < trials; ++t) starts.push_back(fusedet::bench::perturbedStart(in.laserToCamera, maxDeg, maxT, fraction, rng));

  bool pass = true;
  for (const std::string& name : measures) {
    TargetlessOptions opt = base;
    opt.measure = parseAlignmentMeasure(name);
    opt.pyramidLevels = levels;
    opt.estimateUncertainty = false;  // the trials measure the error itself
    std::printf("\nmeasure %s\n", name.c_str());
    std::printf("trial  start_deg  start_m  final_deg  final_m   wall_s   cpu_s  evals   score   final error: rotation vector [deg], translation [m] (camera axes)\n");
    std::vector<double> startDeg, startM, finalDeg, finalM, wall, cpu;
    for (int t = 0; t < trials; ++t) {
      const auto w0 = std::chrono::steady_clock::now();
      const double c0 = cpuSeconds();
      const TargetlessResult r = calibrateTargetless(in.frames, in.K, starts[static_cast<std::size_t>(t)], opt);
      cpu.push_back(cpuSeconds() - c0);
      wall.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - w0).count());
      startDeg.push_back(rotationErrorDeg(starts[static_cast<std::size_t>(t)], in.laserToCamera));
      startM.push_back(translationError(starts[static_cast<std::size_t>(t)], in.laserToCamera));
      finalDeg.push_back(rotationErrorDeg(r.laserToCamera, in.laserToCamera));
      finalM.push_back(translationError(r.laserToCamera, in.laserToCamera));
      const Eigen::Isometry3d e = r.laserToCamera * in.laserToCamera.inverse();
      const Eigen::AngleAxisd aa(e.linear());
      const Eigen::Vector3d w = aa.axis() * aa.angle() * 180.0 / M_PI, dt = e.translation();
      const double score = opt.measure == AlignmentMeasure::kMutualInformation ? r.after.mutualInformation : r.after.edgeAlignment;
      std::printf("%5d  %9.3f  %7.3f  %9.3f  %7.3f  %7.1f  %6.1f  %5d  %6.4f  [%6.3f %6.3f %6.3f] [%6.3f %6.3f %6.3f]\n", t,
                  startDeg.back(), startM.back(), finalDeg.back(), finalM.back(), wall.back(), cpu.back(), r.evaluations,
                  score, w.x(), w.y(), w.z(), dt.x(), dt.y(), dt.z());
      std::fflush(stdout);
    }
    const double mDeg = median(finalDeg), mM = median(finalM);
    std::printf("median %9.3f  %7.3f  %9.3f  %7.3f  %7.1f  %6.1f\n", median(startDeg), median(startM), mDeg, mM,
                median(wall), median(cpu));
    std::printf("bench: calib_%s_median_rotation_error_deg %.4f\n", name.c_str(), mDeg);
    std::printf("bench: calib_%s_median_translation_error_m %.4f\n", name.c_str(), mM);
    std::printf("bench: calib_start_median_rotation_error_deg %.4f\n", median(startDeg));
    std::printf("bench: calib_start_median_translation_error_m %.4f\n", median(startM));
    std::printf("bench: calib_%s_max_trial_wall_s %.2f\n", name.c_str(), *std::max_element(wall.begin(), wall.end()));
    std::printf("bench: calib_%s_max_trial_cpu_s %.2f\n", name.c_str(), *std::max_element(cpu.begin(), cpu.end()));
    if (mDeg > failDeg || mM > failT) {
      std::printf("FAIL: %s median error %.3f deg / %.3f m exceeds %.3f deg / %.3f m\n", name.c_str(), mDeg, mM, failDeg, failT);
      pass = false;
    }
  }
  return pass ? 0 : 1;
}
