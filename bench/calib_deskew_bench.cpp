// SPDX-License-Identifier: Apache-2.0
// Targetless calibration on sweeps as KITTI records them and on the same sweeps moved into the
// scanner's frame at the camera's instant (issue 33: where does the translation's bias come from?).
// KITTI's raw Velodyne sweeps are not corrected for the car's motion during the 0.1 s turn. For
// every frame of the drives with neighbouring sweeps (kitti/: every 3rd frame of drive 0005,
// kitti_0009/: every 2nd of drive 0009), the car's planar motion comes from scan matching the frame's
// sweep against the one before it (`estimatePlanarMotion`; the first frame against the one after),
// then the sweep is de-skewed (`deskewSweep`, the HDL-64E turning clockwise). Printed: per frame the
// motion and where the edge measure peaks along each axis around the calib (0 = the calib is its
// best), as recorded and de-skewed; per drive their mean and spread; then calibration trials from
// random subsets and starts, each run on both versions of the same frames. Ends with "bench:" lines.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "calib_starts.h"
#include "fusedet/core/percentile.h"
#include "fusedet/fusion/calibration/calib_targetless.h"
#include "fusedet/fusion/calibration/score_profile.h"
#include "fusedet/fusion/calibration/sweep_motion.h"
#include "fusedet/fusion/datasets/kitti.h"
#include <opencv2/imgcodecs.hpp>

namespace {

using namespace fusedet::fusion;
using fusedet::percentile;
namespace fs = std::filesystem;

constexpr double kFramePeriod = 0.1;  // [s] KITTI records at 10 Hz; the Velodyne turns once per frame

struct DriveFrames {
  std::string name;
  std::vector<CalibFrame> recorded, deskewed;
  std::vector<PlanarMotion> motion;
};

// Peak of the edge measure along each axis around the reference: offsets in deg / cm.
Eigen::Matrix<double, 6, 1> edgePeaks(const CalibFrame& frame, const Eigen::Matrix3d& K, const Eigen::Isometry3d& reference) {
  const ScoreProfile p = scoreProfile({frame}, K, reference);
  Eigen::Matrix<double, 6, 1> peak;
  for (int a = 0; a < 6; ++a) peak(a) = p.peakOffset(a, false) * (a < 3 ? 1.0 : 100.0);
  return peak;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Targetless calibration on KITTI sweeps as recorded and de-skewed by the car's own motion during the turn."};
  const std::string data = FUSEDET_DATA_DIR;
  std::vector<std::string> dirs = {data + "/kitti", data + "/kitti_0009"};
  int trials = 20, minFrames = 6, maxFrames = 10, every = 1;
  unsigned seed = 43;
  double maxDeg = 2.0, maxT = 0.10, limitDeg = 0.3, limitT = 0.03;
  app.add_option("--kitti", dirs, "KITTI-layout directories of consecutive frames of one drive each, full sweeps")
      ->capture_default_str();
  app.add_option("--trials", trials, "calibration trials (random subsets and starts), each on both versions")->capture_default_str();
  app.add_option("--min-frames", minFrames, "smallest subset")->capture_default_str();
  app.add_option("--max-frames", maxFrames, "largest subset")->capture_default_str();
  std::string spin = "clockwise";
  app.add_option("--spin", spin, "which way the beam turns, seen from above (the other way is the check that the sense matters)")
      ->capture_default_str()
      ->check(CLI::IsMember({"clockwise", "counter-clockwise"}));
  app.add_option("--every", every, "use every n-th frame of each directory (its motion still from the sweep before it)")
      ->capture_default_str()
      ->check(CLI::PositiveNumber);
  app.add_option("--seed", seed, "random seed of subsets and starts")->capture_default_str();
  app.add_option("--max-deg", maxDeg, "largest start rotation error [deg]")->capture_default_str();
  app.add_option("--max-m", maxT, "largest start translation error [m]")->capture_default_str();
  CLI11_PARSE(app, argc, argv);
  if (minFrames < 3 || maxFrames < minFrames) {
    std::fprintf(stderr, "need 3 <= --min-frames <= --max-frames\n");
    return 2;
  }

  std::vector<DriveFrames> drives;
  Eigen::Matrix3d K = Eigen::Matrix3d::Zero();
  Eigen::Isometry3d truth = Eigen::Isometry3d::Identity();
  for (const std::string& dir : dirs) {
    const fs::path root(dir);
    const std::vector<std::string> ids = listKittiFrames(root);
    if (ids.size() < 2) {
      std::fprintf(stderr, "%s: fewer than 2 frames, no motion to estimate\n", dir.c_str());
      return 2;
    }
    DriveFrames d;
    d.name = root.filename().string();
    std::vector<Sweep> sweeps;
    for (const std::string& id : ids) sweeps.push_back(readKittiVelodyne(root / "velodyne" / (id + ".bin")));
    for (std::size_t i = 0; i < ids.size(); i += static_cast<std::size_t>(every)) {
      const std::size_t a = i == 0 ? 0 : i - 1, b = i == 0 ? 1 : i;
      const double seconds = kFramePeriod * (std::stod(ids[b]) - std::stod(ids[a]));
      const PlanarMotion m = estimatePlanarMotion(sweeps[a], sweeps[b], seconds);
      CalibFrame f;
      f.name = d.name + "/" + ids[i];
      f.image = cv::imread((root / "image_2" / (ids[i] + ".png")).string(), cv::IMREAD_COLOR);
      if (f.image.empty()) {
        std::fprintf(stderr, "%s: cannot read the image of frame %s\n", dir.c_str(), ids[i].c_str());
        return 1;
      }
      f.sweep = sweeps[i];
      if (K.isZero()) {
        const PinholeProjection p = kittiProjection(readKittiCalib(root / "calib" / (ids[i] + ".txt")), f.image.cols, f.image.rows);
        K = p.K;
        truth = p.sweepToCamera;
      }
      CalibFrame g = f;
      deskewSweep(g.sweep, m, kFramePeriod, spin == "clockwise" ? SpinSense::kClockwise : SpinSense::kCounterClockwise);
      d.recorded.push_back(std::move(f));
      d.deskewed.push_back(std::move(g));
      d.motion.push_back(m);
    }
    drives.push_back(std::move(d));
  }

  std::printf("de-skewed with the beam turning %s\n", spin.c_str());
  std::printf("frame            speed  yaw_rate | edge peak, recorded: rx ry rz [deg] tx ty tz [cm] | de-skewed: the same\n");
  std::printf("                 [m/s]  [deg/s]  |\n");
  for (const DriveFrames& d : drives) {
    std::vector<double> sum[2] = {std::vector<double>(6), std::vector<double>(6)}, sq[2] = {std::vector<double>(6), std::vector<double>(6)};
    for (std::size_t i = 0; i < d.recorded.size(); ++i) {
      const Eigen::Matrix<double, 6, 1> p0 = edgePeaks(d.recorded[i], K, truth), p1 = edgePeaks(d.deskewed[i], K, truth);
      std::printf("%-16s %5.2f %8.2f  | %5.2f %5.2f %5.2f %5.1f %5.1f %5.1f | %5.2f %5.2f %5.2f %5.1f %5.1f %5.1f\n",
                  d.recorded[i].name.c_str(), std::hypot(d.motion[i].vx, d.motion[i].vy), d.motion[i].yawRate * 180 / M_PI,
                  p0(0), p0(1), p0(2), p0(3), p0(4), p0(5), p1(0), p1(1), p1(2), p1(3), p1(4), p1(5));
      for (int a = 0; a < 6; ++a) {
        sum[0][a] += p0(a), sq[0][a] += p0(a) * p0(a);
        sum[1][a] += p1(a), sq[1][a] += p1(a) * p1(a);
      }
    }
    const double n = static_cast<double>(d.recorded.size());
    for (int v = 0; v < 2; ++v) {
      std::printf("%-11s %-10s mean (sd):", d.name.c_str(), v == 0 ? "recorded" : "de-skewed");
      for (int a = 0; a < 6; ++a) {
        const double mean = sum[v][a] / n;
        std::printf(" %6.2f (%4.2f)", mean, std::sqrt(std::max(0.0, sq[v][a] / n - mean * mean)));
      }
      std::printf("\n");
      std::printf("bench: calib_deskew_%s_%s_tx_peak_mean_cm %.2f\n", d.name.c_str(), v == 0 ? "recorded" : "deskewed", sum[v][3] / n);
      std::printf("bench: calib_deskew_%s_%s_tz_peak_sd_cm %.2f\n", d.name.c_str(), v == 0 ? "recorded" : "deskewed",
                  std::sqrt(std::max(0.0, sq[v][5] / n - (sum[v][5] / n) * (sum[v][5] / n))));
    }
  }

  // Trials: the same random subset and start for both versions.
  std::vector<std::pair<std::size_t, std::size_t>> pool;
  for (std::size_t d = 0; d < drives.size(); ++d)
    for (std::size_t i = 0; i < drives[d].recorded.size(); ++i) pool.emplace_back(d, i);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> size(minFrames, std::min<int>(maxFrames, static_cast<int>(pool.size())));
  std::vector<double> err[2][6];
  int within[2] = {0, 0};
  std::printf("\ntrial frames | recorded: error rx ry rz [deg] tx ty tz [cm] | de-skewed: the same\n");
  for (int t = 0; t < trials; ++t) {
    std::vector<std::size_t> order(pool.size());
    for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::shuffle(order.begin(), order.end(), rng);
    order.resize(static_cast<std::size_t>(size(rng)));
    std::sort(order.begin(), order.end());
    const Eigen::Isometry3d start = fusedet::bench::perturbedStart(truth, maxDeg, maxT, 0.0, rng);
    std::printf("%5d %6zu |", t, order.size());
    for (int v = 0; v < 2; ++v) {
      std::vector<CalibFrame> frames;
      for (std::size_t k : order) {
        const DriveFrames& d = drives[pool[k].first];
        frames.push_back((v == 0 ? d.recorded : d.deskewed)[pool[k].second]);
      }
      TargetlessOptions opt;
      opt.estimateUncertainty = false;
      const TargetlessResult r = calibrateTargetless(frames, K, start, opt);
      const Eigen::Matrix<double, 6, 1> e = poseDifference(r.laserToCamera, truth);
      for (int a = 0; a < 6; ++a) err[v][a].push_back(std::abs(e(a)) * (a < 3 ? 1.0 : 100.0));
      within[v] += rotationErrorDeg(r.laserToCamera, truth) <= limitDeg && translationError(r.laserToCamera, truth) <= limitT;
      std::printf(" %6.3f %6.3f %6.3f %5.1f %5.1f %5.1f %s", e(0), e(1), e(2), 100 * e(3), 100 * e(4), 100 * e(5), v == 0 ? "|" : "\n");
    }
    std::fflush(stdout);
  }
  if (trials > 0) {
    const char* names[6] = {"rx", "ry", "rz", "tx", "ty", "tz"};
    std::printf("\naxis  |error| p50 / p90, recorded -> de-skewed (deg or cm)\n");
    for (int a = 0; a < 6; ++a)
      std::printf("%-4s  %6.3f / %6.3f -> %6.3f / %6.3f\n", names[a], percentile(err[0][a], 0.50), percentile(err[0][a], 0.90),
                  percentile(err[1][a], 0.50), percentile(err[1][a], 0.90));
    std::printf("within %.2f deg / %.3f m: recorded %d of %d, de-skewed %d of %d\n", limitDeg, limitT, within[0], trials, within[1], trials);
    std::printf("bench: calib_deskew_trials %d\n", trials);
    std::printf("bench: calib_deskew_recorded_within %d\n", within[0]);
    std::printf("bench: calib_deskew_deskewed_within %d\n", within[1]);
    std::printf("bench: calib_deskew_recorded_tx_p50_cm %.2f\n", percentile(err[0][3], 0.50));
    std::printf("bench: calib_deskew_deskewed_tx_p50_cm %.2f\n", percentile(err[1][3], 0.50));
  }
  return 0;
}
