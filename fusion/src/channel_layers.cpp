#include "fusedet/fusion/channel_layers.h"

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <opencv2/imgproc.hpp>
#include <random>
#include <stdexcept>

namespace fusedet::fusion {

void addGradientChannels(LayerStack& stack, const ChannelConfig& config) {
  if (!(config.gradientScale > 0 && config.gradientScale <= 1))
    throw std::invalid_argument("gradient channels: scale must be in (0, 1]");
  const cv::Mat& intensity = stack.at(layer::kIntensity).data;
  cv::Mat grey;
  const int w = std::max(1, static_cast<int>(std::lround(intensity.cols * config.gradientScale)));
  const int h = std::max(1, static_cast<int>(std::lround(intensity.rows * config.gradientScale)));
  cv::Mat reduced = intensity;
  if (w != intensity.cols || h != intensity.rows) cv::resize(intensity, reduced, cv::Size(w, h), 0, 0, cv::INTER_AREA);
  reduced.convertTo(grey, CV_32F);
  cv::Mat mag(h, w, CV_8UC1, cv::Scalar(0));
  std::array<cv::Mat, 6> oriented;
  for (cv::Mat& o : oriented) o = cv::Mat(h, w, CV_8UC1, cv::Scalar(0));
  constexpr double kBin = std::numbers::pi / 6;
  for (int y = 0; y < h; ++y) {
    const float* up = grey.ptr<float>(std::max(0, y - 1));
    const float* row = grey.ptr<float>(y);
    const float* down = grey.ptr<float>(std::min(h - 1, y + 1));
    for (int x = 0; x < w; ++x) {
      // Central differences, one-sided at the border (replicated edge).
      const double gx = row[std::min(w - 1, x + 1)] - row[std::max(0, x - 1)];
      const double gy = down[x] - up[x];
      const double m = std::sqrt(gx * gx + gy * gy) / std::numbers::sqrt2;  // <= 255
      const auto v = static_cast<std::uint8_t>(std::min(255.0, std::round(m)));
      if (v == 0) continue;
      mag.at<std::uint8_t>(y, x) = v;
      double theta = std::atan2(gy, gx);  // (-pi, pi]; orientation modulo pi
      if (theta < 0) theta += std::numbers::pi;
      const int bin = std::min(5, static_cast<int>(theta / kBin));
      oriented[static_cast<std::size_t>(bin)].at<std::uint8_t>(y, x) = v;
    }
  }
  stack.set(Layer{std::string(channel::kGradientMagnitude), mag, {}});
  for (std::size_t k = 0; k < oriented.size(); ++k)
    stack.set(Layer{std::string(channel::kOrientedGradient[k]), oriented[k], {}});
}

std::vector<Eigen::Vector3d> distanceCellPoints(const LayerStack& stack, const Eigen::Matrix3d& K) {
  const Layer& d = stack.at(layer::kDistance);
  const Eigen::Matrix3d Kinv = K.inverse();
  const double sx = double(stack.width()) / d.width(), sy = double(stack.height()) / d.height();
  std::vector<Eigen::Vector3d> pts;
  for (int r = 0; r < d.height(); ++r)
    for (int c = 0; c < d.width(); ++c) {
      if (d.hasMask() && !d.valid.at<std::uint8_t>(r, c)) continue;
      const float dist = d.data.at<float>(r, c);
      if (!(dist > 0)) continue;
      const Eigen::Vector3d ray = Kinv * Eigen::Vector3d((c + 0.5) * sx, (r + 0.5) * sy, 1.0);
      pts.push_back(ray.normalized() * double(dist));
    }
  return pts;
}

std::optional<GroundPlane> fitGroundPlane(const std::vector<Eigen::Vector3d>& pts, const ChannelConfig& config) {
  if (pts.size() < 3) return std::nullopt;
  const Eigen::Vector3d up(0, -1, 0);
  const double minCos = std::cos(30.0 * std::numbers::pi / 180.0);
  std::mt19937_64 rng(12345);  // fixed: the same stack gives the same layer
  std::uniform_int_distribution<std::size_t> pick(0, pts.size() - 1);
  // Inliers are counted on a subsample for speed; the refit uses all of them.
  const std::size_t stride = std::max<std::size_t>(1, pts.size() / 4000);
  GroundPlane best;
  bool found = false;
  for (int it = 0; it < config.ransacIterations; ++it) {
    const Eigen::Vector3d& a = pts[pick(rng)];
    const Eigen::Vector3d& b = pts[pick(rng)];
    const Eigen::Vector3d& c = pts[pick(rng)];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-9) continue;
    n.normalize();
    if (n.dot(up) < 0) n = -n;
    if (n.dot(up) < minCos) continue;
    const double off = -n.dot(a);
    int count = 0;
    for (std::size_t i = 0; i < pts.size(); i += stride)
      if (std::abs(n.dot(pts[i]) + off) < config.groundInlier) ++count;
    if (!found || count > best.inliers) {
      best = GroundPlane{n, off, count};
      found = true;
    }
  }
  if (!found) return std::nullopt;
  // Least-squares refit on all inliers: centroid + smallest principal direction.
  std::vector<Eigen::Vector3d> in;
  for (const auto& p : pts)
    if (std::abs(best.normal.dot(p) + best.offset) < config.groundInlier) in.push_back(p);
  if (in.size() >= 3) {
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const auto& p : in) mean += p;
    mean /= double(in.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& p : in) cov += (p - mean) * (p - mean).transpose();
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    Eigen::Vector3d n = es.eigenvectors().col(0);
    if (n.dot(up) < 0) n = -n;
    if (n.dot(up) >= minCos) best = GroundPlane{n, -n.dot(mean), static_cast<int>(in.size())};
  }
  return best;
}

void addLaserChannels(LayerStack& stack, const Eigen::Matrix3d& K, const ChannelConfig& config) {
  const Layer d = stack.at(layer::kDistance);  // a copy (shared pixels): set() below may move the stack's layers
  const int w = d.width(), h = d.height();
  cv::Mat valid = d.hasMask() ? d.valid.clone() : cv::Mat(h, w, CV_8UC1, cv::Scalar(255));
  // Depth gradient: central differences where both neighbours are measured, else one-sided.
  cv::Mat grad(h, w, CV_32FC1, cv::Scalar(0));
  auto ok = [&](int r, int c) { return r >= 0 && c >= 0 && r < h && c < w && valid.at<std::uint8_t>(r, c); };
  auto at = [&](int r, int c) { return double(d.data.at<float>(r, c)); };
  auto diff = [&](int r, int c, int dr, int dc) {
    const bool a = ok(r - dr, c - dc), b = ok(r + dr, c + dc);
    if (a && b) return (at(r + dr, c + dc) - at(r - dr, c - dc)) / 2;
    if (b) return at(r + dr, c + dc) - at(r, c);
    if (a) return at(r, c) - at(r - dr, c - dc);
    return 0.0;
  };
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c)
      if (ok(r, c)) grad.at<float>(r, c) = static_cast<float>(std::hypot(diff(r, c, 0, 1), diff(r, c, 1, 0)));
  stack.set(Layer{std::string(channel::kDistanceGradient), grad, valid});

  cv::Mat height(h, w, CV_32FC1, cv::Scalar(0));
  cv::Mat heightValid = valid.clone();
  const std::optional<GroundPlane> plane = fitGroundPlane(distanceCellPoints(stack, K), config);
  if (!plane) {
    heightValid.setTo(0);
  } else {
    const Eigen::Matrix3d Kinv = K.inverse();
    const double sx = double(stack.width()) / w, sy = double(stack.height()) / h;
    for (int r = 0; r < h; ++r)
      for (int c = 0; c < w; ++c) {
        if (!ok(r, c)) continue;
        const Eigen::Vector3d p =
            (Kinv * Eigen::Vector3d((c + 0.5) * sx, (r + 0.5) * sy, 1.0)).normalized() * at(r, c);
        height.at<float>(r, c) = static_cast<float>(plane->normal.dot(p) + plane->offset);
      }
  }
  stack.set(Layer{std::string(channel::kHeight), height, heightValid});
}

}  // namespace fusedet::fusion
