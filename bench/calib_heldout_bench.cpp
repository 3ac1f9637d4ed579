// SPDX-License-Identifier: Apache-2.0
// Targetless calibration on frames it was never tuned on (issue 33): the rig's KITTI frames split
// by raw drive into the drives its measures and parameters were chosen on (the frames of issue 17's
// acceptance run, bench_calib_kitti, and every frame of their drives: `--half choose`) and all
// other drives (`--half report`). Each trial draws a random subset of one half's frames and a start
// off the calib by up to --max-deg / --max-m in a random direction, calibrates, and compares every
// axis's error with the 1-sigma the tool reports. Printed: per trial the errors, sigmas and the
// axes the tool flags (1-sigma above the limits); per axis the error percentiles and how often the
// 1-sigma covers the error; how many trials end within the limits, how many outside are flagged
// or held, and how many are silently wrong by more than 3 sigma. Ends with "bench:" lines.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "calib_starts.h"
#include "fusedet/core/cpu_time.h"
#include "fusedet/core/percentile.h"
#include "fusedet/fusion/calibration/calib_kitti.h"
#include "fusedet/fusion/calibration/calib_targetless.h"
#include "fusedet/fusion/datasets/kitti_drives.h"

namespace {

using namespace fusedet::fusion;
using fusedet::percentile;
namespace fs = std::filesystem;

// Raw drive of a calibration frame named "<dir name>/<id>".
std::string driveOfFrame(const std::string& name, const std::map<std::string, KittiDriveMap>& maps) {
  const std::string dir = name.substr(0, name.find('/')), id = name.substr(name.find('/') + 1);
  const auto it = maps.find(dir);
  return it == maps.end() ? dir : it->second.driveOf(id, dir);
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Targetless calibration on held-out drives: per-axis errors against the calib, and whether the "
               "reported 1-sigma covers them."};
  const std::string data = FUSEDET_DATA_DIR;
  std::vector<std::string> dirs = {data + "/kitti", data + "/kitti_0009", data + "/kitti_object_more",
                                   data + "/kitti_object_sample"};
  std::string half = "report", measure = "edges";
  int trials = 40, minFrames = 6, maxFrames = 10, levels = 1;
  unsigned seed = 33;
  double maxDeg = 2.0, maxT = 0.10, limitDeg = 0.3, limitT = 0.03;
  std::vector<std::string> hold;
  app.add_option("--kitti", dirs, "KITTI-layout directories (frames of the most common rig are used)")->capture_default_str();
  app.add_option("--half", half, "choose: the drives the method was tuned on; report: every other drive")
      ->capture_default_str()
      ->check(CLI::IsMember({"choose", "report"}));
  app.add_option("--trials", trials, "random frame subsets, one start each")->capture_default_str();
  app.add_option("--min-frames", minFrames, "smallest subset")->capture_default_str();
  app.add_option("--max-frames", maxFrames, "largest subset")->capture_default_str();
  app.add_option("--seed", seed, "random seed of subsets and starts")->capture_default_str();
  app.add_option("--max-deg", maxDeg, "largest start rotation error [deg] (drawn from [0, 1] x this)")->capture_default_str();
  app.add_option("--max-m", maxT, "largest start translation error [m] (drawn from [0, 1] x this)")->capture_default_str();
  app.add_option("--measure", measure, "mi, edges, both")->capture_default_str();
  app.add_option("--levels", levels, "pyramid levels")->capture_default_str();
  app.add_option("--hold", hold, "axes kept at the start: rx ry rz tx ty tz, comma-separated")->delimiter(',');
  app.add_option("--limit-deg", limitDeg, "a trial is within the limits at this rotation error [deg]; an axis is flagged "
                                          "when its 1-sigma exceeds it")->capture_default_str();
  app.add_option("--limit-m", limitT, "likewise for translation [m]")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (minFrames < 3 || maxFrames < minFrames) {
    std::fprintf(stderr, "need 3 <= --min-frames <= --max-frames (the 1-sigma needs 3 frames)\n");
    return 2;
  }

  const std::vector<fs::path> roots(dirs.begin(), dirs.end());
  std::map<std::string, KittiDriveMap> maps;
  for (const fs::path& r : roots) maps[(r.has_filename() ? r : r.parent_path()).filename().string()] = readKittiDriveMap(r);
  std::set<std::string> tunedDrives;
  for (const CalibFrame& f : loadKittiCalibrationInput(roots, 10).frames) tunedDrives.insert(driveOfFrame(f.name, maps));
  KittiCalibrationInput all = loadKittiCalibrationInput(roots, 100000);
  std::vector<CalibFrame> pool;
  std::set<std::string> poolDrives;
  for (CalibFrame& f : all.frames) {
    const std::string drive = driveOfFrame(f.name, maps);
    if (tunedDrives.count(drive) == (half == "choose" ? 1u : 0u)) {
      poolDrives.insert(drive);
      pool.push_back(std::move(f));
    }
  }
  std::printf("rig: %zu frames (%zu of other rigs skipped); tuned on the drives of issue 17's 10 frames:", all.rigFrames,
              all.otherRigFrames);
  for (const std::string& d : tunedDrives) std::printf(" %s", d.c_str());
  std::printf("\nhalf %s: %zu frames of %zu drives\n", half.c_str(), pool.size(), poolDrives.size());
  if (pool.size() < static_cast<std::size_t>(minFrames)) {
    std::fprintf(stderr, "the %s half has %zu frames, fewer than --min-frames %d\n", half.c_str(), pool.size(), minFrames);
    return 2;
  }

  TargetlessOptions opt;
  opt.measure = parseAlignmentMeasure(measure);
  opt.pyramidLevels = levels;
  opt.hold = parseCalibAxes(hold);
  const bool anyHeld = std::count(opt.hold.begin(), opt.hold.end(), true) > 0;
  std::printf("starts: calib perturbed by 0..%.2f deg and 0..%.3f m in random directions; subsets of %d-%d frames; "
              "seed %u; measure %s; limits %.2f deg / %.3f m; one thread\n\n",
              maxDeg, maxT, minFrames, std::min<int>(maxFrames, static_cast<int>(pool.size())), seed, measure.c_str(), limitDeg,
              limitT);
  std::printf("trial frames start_deg start_m  err_deg  err_m   error rx ry rz [deg] tx ty tz [cm] | 1-sigma the same | flagged  cpu_s\n");

  std::mt19937 rng(seed);
  std::vector<double> err[6], covered[6];
  int within = 0, flaggedOutside = 0, heldOutside = 0, silentOutside = 0, silentBeyond3Sigma = 0, flaggedTrials = 0;
  double cpuTotal = 0;
  for (int t = 0; t < trials; ++t) {
    std::uniform_int_distribution<int> size(minFrames, std::min<int>(maxFrames, static_cast<int>(pool.size())));
    std::vector<std::size_t> order(pool.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(static_cast<std::size_t>(size(rng)));
    std::sort(order.begin(), order.end());
    std::vector<CalibFrame> frames;
    for (std::size_t i : order) frames.push_back(pool[i]);
    const Eigen::Isometry3d start = fusedet::bench::perturbedStart(all.laserToCamera, maxDeg, maxT, 0.0, rng);

    const double c0 = fusedet::processCpuMs() / 1000.0;
    const TargetlessResult r = calibrateTargetless(frames, all.K, start, opt);
    const double cpu = fusedet::processCpuMs() / 1000.0 - c0;
    cpuTotal += cpu;
    const Eigen::Matrix<double, 6, 1> e = poseDifference(r.laserToCamera, all.laserToCamera), s = sigmaPerAxis(r);
    const CalibAxes flagged = uncertainAxes(r, opt.hold, limitDeg, limitT);
    const double eDeg = rotationErrorDeg(r.laserToCamera, all.laserToCamera), eM = translationError(r.laserToCamera, all.laserToCamera);
    const bool ok = eDeg <= limitDeg && eM <= limitT;
    const bool isFlagged = std::count(flagged.begin(), flagged.end(), true) > 0;
    bool beyond3Sigma = false;
    for (int a = 0; a < 6; ++a) {
      err[a].push_back(std::abs(e(a)));
      if (!opt.hold[static_cast<std::size_t>(a)]) covered[a].push_back(std::abs(e(a)) <= s(a) ? 1.0 : 0.0);
      if (!opt.hold[static_cast<std::size_t>(a)] && std::abs(e(a)) > 3 * s(a)) beyond3Sigma = true;
    }
    flaggedTrials += isFlagged;
    if (ok) ++within;
    else if (isFlagged) ++flaggedOutside;
    else if (anyHeld) ++heldOutside;
    else ++silentOutside;
    if (!ok && !isFlagged && beyond3Sigma) ++silentBeyond3Sigma;
    const std::string names = calibAxisList(flagged, ",");
    std::printf("%5d %6zu %9.2f %7.3f %8.3f %6.3f   %6.3f %6.3f %6.3f %5.1f %5.1f %5.1f | %5.3f %5.3f %5.3f %4.1f %4.1f %4.1f | %-8s %5.1f\n",
                t, frames.size(), rotationErrorDeg(start, all.laserToCamera), translationError(start, all.laserToCamera), eDeg,
                eM, e(0), e(1), e(2), 100 * e(3), 100 * e(4), 100 * e(5), s(0), s(1), s(2), 100 * s(3), 100 * s(4),
                100 * s(5), names.empty() ? "-" : names.c_str(), cpu);
    std::fflush(stdout);
  }

  std::printf("\naxis  |error| p50    p90    p95    max   (deg or cm)   1-sigma covers the error\n");
  for (int a = 0; a < 6; ++a) {
    const double k = a < 3 ? 1.0 : 100.0;
    double cover = 0;
    for (double c : covered[a]) cover += c;
    std::printf("%-4s  %10.3f %6.3f %6.3f %6.3f   %13s   %s\n", calibAxisName(a), k * percentile(err[a], 0.50),
                k * percentile(err[a], 0.90), k * percentile(err[a], 0.95), k * percentile(err[a], 1.0), "",
                covered[a].empty() ? "held" : (std::to_string(static_cast<int>(std::lround(100 * cover / static_cast<double>(covered[a].size())))) + " %").c_str());
  }
  std::printf("\n%d of %d trials within %.2f deg / %.3f m; outside: %d flagged, %d held, %d silent (%d of them wrong by "
              "more than 3 sigma on an axis); %d trials flagged in all\n",
              within, trials, limitDeg, limitT, flaggedOutside, heldOutside, silentOutside, silentBeyond3Sigma, flaggedTrials);
  std::printf("bench: calib_heldout_%s_within_share %.3f\n", half.c_str(), static_cast<double>(within) / trials);
  std::printf("bench: calib_heldout_%s_outside_flagged %d\n", half.c_str(), flaggedOutside);
  std::printf("bench: calib_heldout_%s_outside_silent %d\n", half.c_str(), silentOutside);
  std::printf("bench: calib_heldout_%s_silent_beyond_3_sigma %d\n", half.c_str(), silentBeyond3Sigma);
  for (int a = 0; a < 6; ++a) {
    double cover = 0;
    for (double c : covered[a]) cover += c;
    if (!covered[a].empty())
      std::printf("bench: calib_heldout_%s_sigma_covers_%s %.3f\n", half.c_str(), calibAxisName(a),
                  cover / static_cast<double>(covered[a].size()));
  }
  std::printf("bench: calib_heldout_%s_cpu_s_per_trial %.2f\n", half.c_str(), cpuTotal / trials);
  return 0;
}
