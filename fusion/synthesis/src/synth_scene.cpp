// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/synthesis/synth_scene.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace fusedet::fusion {

namespace {
constexpr double kMaxRange = 120.0;
constexpr float kGroundRemission = 0.25f;
}  // namespace

ProceduralScene::ProceduralScene(double shift) {
  const double g = kGroundZ;
  auto box = [&](double x0, double y0, double x1, double y1, double h, float rem, cv::Vec3b c) {
    boxes_.push_back(Box{{x0 - shift, y0, g}, {x1 - shift, y1, g + h}, rem, c});
  };
  box(10, -4.0, 14.2, -2.2, 1.5, 0.6f, {40, 40, 200});     // a car-sized box, right, red
  box(18, 2.0, 22.5, 3.9, 1.6, 0.5f, {200, 60, 30});       // another one, left, blue
  box(7, 1.2, 7.6, 1.8, 1.8, 0.35f, {60, 180, 60});        // a person-sized post, green
  box(35, -15, 36, 15, 6.0, 0.8f, {170, 170, 170});        // back wall, grey
}

std::optional<std::pair<double, int>> ProceduralScene::hit(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  double best = kMaxRange;
  int what = -2;
  if (d.z() < -1e-9) {
    const double t = (kGroundZ - o.z()) / d.z();
    if (t > 0 && t < best) best = t, what = -1;
  }
  for (std::size_t i = 0; i < boxes_.size(); ++i) {  // slab test
    double t0 = 0, t1 = best;
    bool miss = false;
    for (int k = 0; k < 3 && !miss; ++k) {
      if (std::abs(d[k]) < 1e-12) {
        miss = o[k] < boxes_[i].min[k] || o[k] > boxes_[i].max[k];
        continue;
      }
      double a = (boxes_[i].min[k] - o[k]) / d[k], b = (boxes_[i].max[k] - o[k]) / d[k];
      if (a > b) std::swap(a, b);
      t0 = std::max(t0, a);
      t1 = std::min(t1, b);
      miss = t0 > t1;
    }
    if (!miss && t0 > 0 && t0 < best) best = t0, what = static_cast<int>(i);
  }
  if (what == -2) return std::nullopt;
  return std::make_pair(best, what);
}

std::optional<RayHit> ProceduralScene::cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d) const {
  auto h = hit(o, d);
  if (!h) return std::nullopt;
  return RayHit{h->first, h->second < 0 ? kGroundRemission : boxes_[static_cast<std::size_t>(h->second)].remission, 0};
}

cv::Mat ProceduralScene::render(const CameraModel& camera, const Eigen::Isometry3d& baseToCamera) const {
  cv::Mat img(camera.height, camera.width, CV_8UC3);
  const Eigen::Isometry3d camToBase = baseToCamera.inverse();
  const Eigen::Vector3d o = camToBase.translation();
  const Eigen::Matrix3d kInv = camera.K.inverse();
  for (int v = 0; v < camera.height; ++v) {
    auto* row = img.ptr<cv::Vec3b>(v);
    for (int u = 0; u < camera.width; ++u) {
      const Eigen::Vector3d d = (camToBase.linear() * (kInv * Eigen::Vector3d(u + 0.5, v + 0.5, 1.0))).normalized();
      const auto h = hit(o, d);
      if (!h) {
        row[u] = cv::Vec3b(235, 206, 135);  // sky
      } else if (h->second < 0) {
        const Eigen::Vector3d p = o + h->first * d;  // ground: a checker pattern for texture
        const bool dark = (static_cast<int>(std::floor(p.x())) + static_cast<int>(std::floor(p.y()))) % 2 == 0;
        row[u] = dark ? cv::Vec3b(90, 90, 90) : cv::Vec3b(120, 120, 120);
      } else {
        row[u] = boxes_[static_cast<std::size_t>(h->second)].colour;
      }
    }
  }
  return img;
}

}  // namespace fusedet::fusion
