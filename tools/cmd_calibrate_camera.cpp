// SPDX-License-Identifier: Apache-2.0
// fusedet calibrate-camera: camera intrinsics from photographs of a chessboard; writes the
// camera calibration YAML (ROS camera_info) that the config's camera.calibration names.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "command.h"
#include "fusedet/fusion/calibration/board_corners.h"
#include "fusedet/fusion/calibration/camera_intrinsics.h"
#include "fusedet/fusion/camera_model.h"

namespace fusedet::tools {
namespace {

namespace fs = std::filesystem;

struct CalibrateCameraOptions {
  std::vector<fs::path> images;
  std::string board = "9x6";
  double squareM = 0.025;
  fs::path out;
  std::string name = "camera";
};

// Files as given; a directory stands for its .png/.jpg/.jpeg/.bmp/.pgm files in name order.
std::vector<fs::path> imageFiles(const std::vector<fs::path>& given) {
  std::vector<fs::path> files;
  for (const fs::path& p : given) {
    if (!fs::is_directory(p)) {
      files.push_back(p);
      continue;
    }
    std::vector<fs::path> inDir;
    for (const auto& e : fs::directory_iterator(p)) {
      std::string ext = e.path().extension().string();
      std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
      if (e.is_regular_file() && (ext == ".png" || ext == ".jpg" || ext == ".jpeg" || ext == ".bmp" || ext == ".pgm"))
        inDir.push_back(e.path());
    }
    std::sort(inDir.begin(), inDir.end());
    files.insert(files.end(), inDir.begin(), inDir.end());
  }
  return files;
}

int runCalibrateCamera(const CalibrateCameraOptions& o) {
  const fusion::BoardSpec board = fusion::parseBoardSize(o.board, o.squareM);
  std::vector<std::vector<cv::Point2f>> views;
  std::vector<fs::path> used;
  cv::Size size;
  for (const fs::path& file : imageFiles(o.images)) {
    cv::Size s;
    const auto corners = fusion::findBoardCorners(file, board, &s);
    if (size.area() != 0 && s != size)
      throw std::runtime_error(file.string() + ": " + std::to_string(s.width) + "x" + std::to_string(s.height) +
                               ", the images before it are " + std::to_string(size.width) + "x" +
                               std::to_string(size.height) + " (one camera, one resolution)");
    size = s;
    if (!corners) {
      std::printf("skipped   %s: no complete %dx%d board\n", file.c_str(), board.cols, board.rows);
      continue;
    }
    views.push_back(*corners);
    used.push_back(file);
  }
  std::printf("views     %zu with the whole board\n", views.size());
  if (views.size() < 3) {
    std::printf("not written: 3 or more views with the whole board are needed (10-20 at different tilts are usual)\n");
    return 3;
  }
  const fusion::IntrinsicsResult r = fusion::calibrateIntrinsics(views, board, size);
  for (std::size_t v = 0; v < views.size(); ++v) std::printf("view      %s: rms %.3f px\n", used[v].c_str(), r.viewRmsPx[v]);
  const Eigen::Matrix3d& K = r.camera.K;
  const auto& d = r.camera.distortion;
  char text[400];
  std::snprintf(text, sizeof text,
                "fx %.3f +- %.3f  fy %.3f +- %.3f  cx %.3f +- %.3f  cy %.3f +- %.3f px\n"
                "distortion k1 %.5f  k2 %.5f  p1 %.6f  p2 %.6f  k3 %.5f\n"
                "rms %.4f px over %zu views, %d iterations",
                K(0, 0), r.sigma(0), K(1, 1), r.sigma(1), K(0, 2), r.sigma(2), K(1, 2), r.sigma(3), d[0], d[1], d[2], d[3],
                d[4], r.rmsPx, views.size(), r.iterations);
  std::printf("%s\n", text);
  std::ostringstream comment;
  comment << "fusedet calibrate-camera: board " << o.board << ", square " << o.squareM << " m\n" << text;
  if (o.out.has_parent_path()) fs::create_directories(o.out.parent_path());
  std::ofstream f(o.out);
  f << fusion::formatCameraModel(r.camera, o.name, comment.str());
  if (!f.flush()) throw std::runtime_error(o.out.string() + ": cannot write");
  fusion::readCameraModel(o.out);  // what fusedetd will read: refuse to leave a file it rejects
  std::printf("wrote     %s\n", o.out.c_str());
  return 0;
}

const bool registered = registerCommand(
    "calibrate-camera", "Camera intrinsics (K, distortion) from photographs of a chessboard; writes camera.yaml",
    [](CLI::App& app) {
      auto o = std::make_shared<CalibrateCameraOptions>();
      app.description(
          "Camera intrinsics from photographs of a printed chessboard. Finds the board's inner corners in each\n"
          "image (OpenCV's chessboard detector, refined to sub-pixel), then fits the pinhole K (fx, fy, cx, cy;\n"
          "no skew) and OpenCV's five distortion coefficients (k1 k2 p1 p2 k3, ROS \"plumb_bob\") with the\n"
          "board's pose in every view: Zhang's closed form from one homography per view, then\n"
          "Levenberg-Marquardt on the squared reprojection error. Images without the whole board are\n"
          "skipped and named.\n\n"
          "Take 10-20 photographs with the camera's own resolution: the board filling a good part of the\n"
          "image, tilted by 20-45 degrees in different directions, and in the corners of the image (that is\n"
          "where distortion shows). A view whose rms stands out is a blurred or misdetected one: drop it.\n"
          "--square only scales the board poses; the intrinsics do not depend on it.\n\n"
          "Writes --out as a ROS camera_info YAML (the file camera.calibration names in the config, read by\n"
          "fusedetd and every fusedet command) with the fit as comments, and reads it back before saying so.\n"
          "On OpenCV's sample photographs (opencv-doc: left01-14.jpg, 9x6) it gives the intrinsics of\n"
          "OpenCV's own calibrateCamera on the same corners (bench_camera_intrinsics, docs/results).\n\n"
          "Exit status: 0 written; 1 on errors (unreadable image, images of different sizes, bad options);\n"
          "3 not written: fewer than 3 views with the whole board.\n\n"
          "Example:\n"
          "  fusedet calibrate-camera --board 9x6 --square 0.025 --out camera.yaml shots/");
      app.add_option("images", o->images, "image files, or directories of .png/.jpg/.jpeg/.bmp/.pgm files")
          ->required()
          ->check(CLI::ExistingPath);
      app.add_option("--board", o->board, "inner corners per row x per column, COLSxROWS (a 10x7-square board has 9x6)")
          ->capture_default_str()
          ->check([](const std::string& v) {
            try {
              fusion::parseBoardSize(v, 1.0);
              return std::string();
            } catch (const std::invalid_argument& e) {
              return std::string(e.what());
            }
          });
      app.add_option("--square", o->squareM, "side of one square [m]")->capture_default_str()->check(CLI::PositiveNumber);
      app.add_option("--out", o->out, "camera calibration YAML to write")->required();
      app.add_option("--name", o->name, "camera_name in the file")->capture_default_str();
      return [o] { return runCalibrateCamera(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
