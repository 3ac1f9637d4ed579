// SPDX-License-Identifier: Apache-2.0
// bench_camera_intrinsics: `fusedet calibrate-camera`'s fit beside OpenCV's cv::calibrateCamera on
// the same chessboard corners of real photographs (default: the samples Debian's opencv-doc ships,
// left01-14.jpg, a 9x6 board): the nine intrinsics side by side, reprojection rms, and the time of
// each fit (one thread each, median of --repeats).

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>

#include "fusedet/fusion/calibration/board_corners.h"
#include "fusedet/fusion/calibration/camera_intrinsics.h"

namespace fs = std::filesystem;
using namespace fusedet::fusion;

namespace {

template <typename F>
double medianMs(int repeats, F&& run) {
  std::vector<double> ms;
  for (int i = 0; i < repeats; ++i) {
    const auto t0 = std::chrono::steady_clock::now();
    run();
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  return ms[ms.size() / 2];
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"Camera intrinsics from chessboard photographs: fusedet's fit beside cv::calibrateCamera on the same corners"};
  fs::path dir = "/usr/share/doc/opencv-doc/examples/data";
  std::string pattern = "left", boardText = "9x6";
  double square = 0.025;
  int repeats = 5;
  app.add_option("--images", dir, "folder of the photographs")->capture_default_str();
  app.add_option("--prefix", pattern, "file names start with this (.jpg/.png)")->capture_default_str();
  app.add_option("--board", boardText, "inner corners COLSxROWS")->capture_default_str();
  app.add_option("--square", square, "square side [m]")->capture_default_str();
  app.add_option("--repeats", repeats, "fits per solver (median time)")->capture_default_str()->check(CLI::Range(1, 100));
  CLI11_PARSE(app, argc, argv);
  cv::setNumThreads(1);  // both fits on one thread

  const BoardSpec board = parseBoardSize(boardText, square);
  std::vector<fs::path> files;
  if (fs::is_directory(dir))
    for (const auto& e : fs::directory_iterator(dir)) {
      const std::string name = e.path().filename().string(), ext = e.path().extension().string();
      if (name.rfind(pattern, 0) == 0 && (ext == ".jpg" || ext == ".png") && name != pattern + ext) files.push_back(e.path());
    }
  std::sort(files.begin(), files.end());
  if (files.empty()) {
    std::fprintf(stderr, "bench_camera_intrinsics: no %s*.jpg/.png in %s (Debian: apt install opencv-doc)\n", pattern.c_str(),
                 dir.c_str());
    return 2;
  }
  std::vector<std::vector<cv::Point2f>> views;
  cv::Size size;
  for (const fs::path& f : files) {
    if (auto c = findBoardCorners(f, board, &size)) views.push_back(*c);
    else std::printf("no whole board: %s\n", f.filename().c_str());
  }
  std::printf("%zu of %zu photographs with the whole %s board, %dx%d\n", views.size(), files.size(), boardText.c_str(),
              size.width, size.height);
  if (views.size() < 3) return 1;

  IntrinsicsResult ours;
  const double oursMs = medianMs(repeats, [&] { ours = calibrateIntrinsics(views, board, size); });
  std::vector<std::vector<cv::Point3f>> object(views.size(), boardPoints(board));
  cv::Mat K, dist;
  double theirRms = 0;
  const double theirMs = medianMs(repeats, [&] {
    std::vector<cv::Mat> rv, tv;
    theirRms = cv::calibrateCamera(object, views, size, K, dist, rv, tv);
  });

  const char* names[9] = {"fx [px]", "fy [px]", "cx [px]", "cy [px]", "k1", "k2", "p1", "p2", "k3"};
  const double o[9] = {ours.camera.K(0, 0), ours.camera.K(1, 1), ours.camera.K(0, 2), ours.camera.K(1, 2),
                       ours.camera.distortion[0], ours.camera.distortion[1], ours.camera.distortion[2],
                       ours.camera.distortion[3], ours.camera.distortion[4]};
  const double t[9] = {K.at<double>(0, 0), K.at<double>(1, 1), K.at<double>(0, 2), K.at<double>(1, 2), dist.at<double>(0),
                       dist.at<double>(1), dist.at<double>(2), dist.at<double>(3), dist.at<double>(4)};
  std::printf("\n| parameter | fusedet | OpenCV calibrateCamera | difference | fusedet 1-sigma |\n|---|---:|---:|---:|---:|\n");
  double worstSigmas = 0;
  for (int k = 0; k < 9; ++k) {
    std::printf("| %s | %.5g | %.5g | %.2g | %.2g |\n", names[k], o[k], t[k], o[k] - t[k], ours.sigma(k));
    worstSigmas = std::max(worstSigmas, std::abs(o[k] - t[k]) / ours.sigma(k));
  }
  std::printf("| rms [px] | %.5f | %.5f | %.2g | |\n| fit [ms] | %.1f | %.1f | | |\n\n", ours.rmsPx, theirRms,
              ours.rmsPx - theirRms, oursMs, theirMs);
  std::printf("bench: camera_intrinsics_views %zu\n", views.size());
  std::printf("bench: camera_intrinsics_rms_px %.5f\n", ours.rmsPx);
  std::printf("bench: camera_intrinsics_opencv_rms_px %.5f\n", theirRms);
  std::printf("bench: camera_intrinsics_max_difference_in_sigmas %.4f\n", worstSigmas);
  std::printf("bench: camera_intrinsics_fit_ms %.2f\n", oursMs);
  std::printf("bench: camera_intrinsics_opencv_fit_ms %.2f\n", theirMs);
  return 0;
}
