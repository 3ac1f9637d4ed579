// SPDX-License-Identifier: Apache-2.0
#include "alignment_cost.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <opencv2/imgproc.hpp>
#include <stdexcept>

namespace fusedet::fusion::detail {
namespace {

constexpr float kMinEdgeJump = 0.3f;       // [m] range step that makes a depth edge
constexpr float kMaxEdgeJump = 10.0f;      // [m] larger steps weigh no more
constexpr float kEdgeSelf = 1.0f / 3.0f;   // weight of the undecayed edge strength (Levinson & Thrun)
constexpr double kImageMargin = 0.15;      // points this far (fraction of the size) outside count

// Range jump from each point to its farthest neighbour on a spherical grid (azimuth x elevation
// cells, the nearest point of a cell stands for it): left, right, above and below, each the first
// occupied cell within reach. A point in front of a farther surface is a depth edge. The grid
// makes no assumption about the scanner's beam order or line pattern.
constexpr double kAzimuthCellDeg = 0.2;
constexpr double kElevationCellDeg = 0.3;
// Reach in cells: 0.4 deg in azimuth, 0.6 deg in elevation (the Velodyne's rings are ~0.4 deg
// apart). A tilting LMS 291 at 1 deg resolution thus gives depth edges across its scan lines
// only: reaching across its 1 deg gaps made the profiles on synthesised logs worse (peaks
// 0.25 deg / 3.5 cm off instead of 0.05 deg / 0.5 cm about and along the camera's y axis).
constexpr int kAzimuthReach = 2;
constexpr int kElevationReach = 2;
constexpr float kStepRatio = 3.f;

struct DepthJump {
  float jump = 0;              // [m] 0 = no depth edge
  std::int32_t farther = -1;   // the neighbour behind the edge
};

std::vector<DepthJump> depthJumps(const Sweep& sweep) {
  const std::size_t n = sweep.points.size();
  std::vector<DepthJump> jump(n);
  if (n == 0) return jump;
  constexpr double kRad = 180.0 / M_PI;
  std::vector<float> range(n);
  std::vector<int> col(n), row(n);
  int rowMin = std::numeric_limits<int>::max(), rowMax = std::numeric_limits<int>::min();
  const int cols = static_cast<int>(std::lround(360.0 / kAzimuthCellDeg));
  for (std::size_t i = 0; i < n; ++i) {
    const SweepPoint& p = sweep.points[i];
    const double xy = std::hypot(double(p.x), double(p.y));
    range[i] = static_cast<float>(std::hypot(xy, double(p.z)));
    col[i] = std::clamp(static_cast<int>((std::atan2(double(p.y), double(p.x)) * kRad + 180.0) / kAzimuthCellDeg), 0, cols - 1);
    row[i] = static_cast<int>(std::floor(std::atan2(double(p.z), xy) * kRad / kElevationCellDeg));
    rowMin = std::min(rowMin, row[i]);
    rowMax = std::max(rowMax, row[i]);
  }
  const int rows = rowMax - rowMin + 1;
  std::vector<std::int32_t> cell(static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols), -1);
  auto at = [&](int r, int c) -> std::int32_t& {
    return cell[static_cast<std::size_t>(r - rowMin) * static_cast<std::size_t>(cols) + static_cast<std::size_t>(c)];
  };
  for (std::size_t i = 0; i < n; ++i) {
    if (!(range[i] > 0)) continue;
    std::int32_t& c = at(row[i], col[i]);
    if (c < 0 || range[i] < range[static_cast<std::size_t>(c)]) c = static_cast<std::int32_t>(i);
  }
  // The first occupied cell within reach in direction (dr, dc); -1 if none.
  auto neighbour = [&](std::size_t i, int dr, int dc) -> std::int32_t {
    const int reach = dr != 0 ? kElevationReach : kAzimuthReach;
    for (int k = 1; k <= reach; ++k) {
      const int r = row[i] + dr * k;
      if (r < rowMin || r > rowMax) break;
      const std::int32_t other = at(r, (col[i] + dc * k + cols) % cols);  // azimuth wraps around
      if (other >= 0) return other;
    }
    return -1;
  };
  auto rangeOf = [&](std::int32_t k) {
    return k < 0 ? std::numeric_limits<float>::quiet_NaN() : range[static_cast<std::size_t>(k)];
  };
  const int dirs[4][2] = {{0, 1}, {0, -1}, {1, 0}, {-1, 0}};
  for (std::size_t i = 0; i < n; ++i) {
    if (at(row[i], col[i]) != static_cast<std::int32_t>(i)) continue;
    for (const auto& d : dirs) {
      const std::int32_t next = neighbour(i, d[0], d[1]);
      const float ahead = rangeOf(next) - range[i];
      if (!(ahead > 0)) continue;
      // A step, not a slope: ground and walls seen at a grazing angle grow in range steadily
      // from ring to ring, so the range must rise much more ahead than it fell behind.
      const float behind = range[i] - rangeOf(neighbour(i, -d[0], -d[1]));
      if (behind > 0 && ahead < kStepRatio * behind) continue;
      if (ahead > jump[i].jump) jump[i] = {ahead, next};
    }
  }
  return jump;
}

// In place: d(x) = max over y of d(y) * decay^chebyshev(x, y), in two raster passes.
void maxDecay(cv::Mat& d, float decay) {
  const int rows = d.rows, cols = d.cols;
  for (int y = 0; y < rows; ++y) {
    float* r = d.ptr<float>(y);
    const float* up = y > 0 ? d.ptr<float>(y - 1) : nullptr;
    for (int x = 0; x < cols; ++x) {
      float m = r[x];
      if (x > 0) m = std::max(m, decay * r[x - 1]);
      if (up) {
        m = std::max(m, decay * up[x]);
        if (x > 0) m = std::max(m, decay * up[x - 1]);
        if (x + 1 < cols) m = std::max(m, decay * up[x + 1]);
      }
      r[x] = m;
    }
  }
  for (int y = rows - 1; y >= 0; --y) {
    float* r = d.ptr<float>(y);
    const float* down = y + 1 < rows ? d.ptr<float>(y + 1) : nullptr;
    for (int x = cols - 1; x >= 0; --x) {
      float m = r[x];
      if (x + 1 < cols) m = std::max(m, decay * r[x + 1]);
      if (down) {
        m = std::max(m, decay * down[x]);
        if (x > 0) m = std::max(m, decay * down[x - 1]);
        if (x + 1 < cols) m = std::max(m, decay * down[x + 1]);
      }
      r[x] = m;
    }
  }
}

// Gradient magnitude scaled so that its 99th percentile is 1, clipped at 1, then spread.
cv::Mat edgeMap(const cv::Mat& intensity, float decay) {
  cv::Mat gx, gy, mag;
  cv::Sobel(intensity, gx, CV_32F, 1, 0, 3);
  cv::Sobel(intensity, gy, CV_32F, 0, 1, 3);
  cv::magnitude(gx, gy, mag);
  std::vector<float> v(mag.begin<float>(), mag.end<float>());
  const auto k = v.begin() + static_cast<std::ptrdiff_t>(v.size() * 99 / 100);
  std::nth_element(v.begin(), k, v.end());
  const float scale = *k > 0 ? 1.f / *k : 1.f;
  cv::Mat e = cv::min(mag * scale, 1.0);
  cv::Mat spread = e.clone();
  maxDecay(spread, decay);
  return kEdgeSelf * e + (1 - kEdgeSelf) * spread;
}

// Bilinear sample with pixel centres at integer coordinates; false outside.
inline bool sample(const cv::Mat& img, float u, float v, float& out) {
  const float fx = std::floor(u), fy = std::floor(v);
  const int x = static_cast<int>(fx), y = static_cast<int>(fy);
  if (x < 0 || y < 0 || x + 1 >= img.cols || y + 1 >= img.rows) return false;
  const float ax = u - fx, ay = v - fy;
  const float* r0 = img.ptr<float>(y);
  const float* r1 = img.ptr<float>(y + 1);
  out = (1 - ay) * ((1 - ax) * r0[x] + ax * r0[x + 1]) + ay * ((1 - ax) * r1[x] + ax * r1[x + 1]);
  return true;
}

// Where the silhouette most likely is: the foreground sample lies inside the object by up to one
// sample spacing, the background sample beyond it; the edge is taken half way between their
// directions, at the foreground's range (else every depth edge sits half a spacing inside its
// object, a bias of ~0.2 deg at the Velodyne's ring spacing, more for sparser scanners).
Eigen::Vector3f silhouettePoint(const SweepPoint& near, const SweepPoint& far) {
  const Eigen::Vector3f a(near.x, near.y, near.z), b(far.x, far.y, far.z);
  return a.norm() * (a.normalized() + b.normalized()).normalized();
}

// Marks points hidden in the camera's view: a nearer point (by more than kOcclusionGap or 10 %)
// projects within kOcclusionFootprintDeg of it. The camera sees from elsewhere than the laser, so
// the laser's background shows through foreground silhouettes, where its image values belong to
// the foreground.
constexpr double kOcclusionFootprintDeg = 0.25;
constexpr float kOcclusionGap = 0.3f;  // [m]

std::vector<bool> occludedInCamera(const std::vector<Eigen::Vector3d>& camera, const Eigen::Matrix3d& K, int width,
                                   int height) {
  const int margin = static_cast<int>(kImageMargin * std::max(width, height)) + 1;
  const int bw = width + 2 * margin, bh = height + 2 * margin;
  const int half = std::max(1, static_cast<int>(std::lround(K(0, 0) * kOcclusionFootprintDeg * M_PI / 180.0)));
  cv::Mat nearest(bh, bw, CV_32F, cv::Scalar(std::numeric_limits<float>::infinity()));
  std::vector<cv::Point> px(camera.size());
  for (std::size_t i = 0; i < camera.size(); ++i) {
    const Eigen::Vector3d p = K * camera[i] / camera[i].z();
    px[i] = {std::clamp(static_cast<int>(std::lround(p.x())) + margin, 0, bw - 1),
             std::clamp(static_cast<int>(std::lround(p.y())) + margin, 0, bh - 1)};
    const float d = static_cast<float>(camera[i].z());
    for (int y = std::max(0, px[i].y - half); y <= std::min(bh - 1, px[i].y + half); ++y) {
      float* row = nearest.ptr<float>(y);
      for (int x = std::max(0, px[i].x - half); x <= std::min(bw - 1, px[i].x + half); ++x) row[x] = std::min(row[x], d);
    }
  }
  std::vector<bool> hidden(camera.size());
  for (std::size_t i = 0; i < camera.size(); ++i) {
    const float d = static_cast<float>(camera[i].z());
    hidden[i] = nearest.at<float>(px[i]) < d - std::max(kOcclusionGap, 0.1f * d);
  }
  return hidden;
}

}  // namespace

std::vector<LaserSamples> prepareLaserSamples(const std::vector<CalibFrame>& frames, const Eigen::Matrix3d& K,
                                              const Eigen::Isometry3d& reference, const TargetlessOptions& options) {
  std::vector<LaserSamples> out(frames.size());
  std::vector<std::vector<float>> remissions(frames.size());
  std::vector<float> all;
  for (std::size_t f = 0; f < frames.size(); ++f) {
    const CalibFrame& frame = frames[f];
    const double w = frame.image.cols, h = frame.image.rows;
    const std::vector<DepthJump> jump = depthJumps(frame.sweep);
    std::vector<std::size_t> chosen;
    std::vector<Eigen::Vector3d> camera;
    for (std::size_t i = 0; i < frame.sweep.points.size(); ++i) {
      const SweepPoint& p = frame.sweep.points[i];
      const Eigen::Vector3d c = reference * Eigen::Vector3d(p.x, p.y, p.z);
      if (!(c.z() >= options.minDepth) || !(c.norm() <= options.maxRange)) continue;
      const Eigen::Vector3d px = K * c / c.z();
      if (px.x() < -kImageMargin * w || px.x() > (1 + kImageMargin) * w || px.y() < -kImageMargin * h ||
          px.y() > (1 + kImageMargin) * h)
        continue;
      chosen.push_back(i);
      camera.push_back(c);
    }
    const std::vector<bool> hidden = options.removeOccluded ? occludedInCamera(camera, K, frame.image.cols, frame.image.rows)
                                                            : std::vector<bool>(camera.size(), false);
    for (std::size_t k = 0; k < chosen.size(); ++k) {
      if (hidden[k]) continue;
      const std::size_t i = chosen[k];
      const SweepPoint& p = frame.sweep.points[i];
      const Eigen::Vector3f xyz(p.x, p.y, p.z);
      out[f].xyz.push_back(xyz);
      remissions[f].push_back(std::clamp(p.remission, 0.f, 1.f));
      if (jump[i].jump >= kMinEdgeJump) {
        out[f].edgeXyz.push_back(options.edgeBetweenSamples ? silhouettePoint(p, frame.sweep.points[static_cast<std::size_t>(jump[i].farther)]) : xyz);
        out[f].edgeWeight.push_back(std::sqrt(std::min(jump[i].jump, kMaxEdgeJump)));
        out[f].edgeWeightSum += out[f].edgeWeight.back();
      } else if (out[f].xyz.size() % kPlainStride == 0) {
        out[f].plainXyz.push_back(xyz);
      }
    }
    all.insert(all.end(), remissions[f].begin(), remissions[f].end());
  }
  if (all.empty()) throw std::invalid_argument("targetless calibration: no laser point lies in front of the camera");
  // Rank quantisation: each remission bin holds about as many points, so the histogram's
  // resolution goes where the values are (KITTI's remission crowds below 0.4).
  std::sort(all.begin(), all.end());
  std::vector<float> edges(kRemissionBins - 1);
  for (int b = 0; b + 1 < kRemissionBins; ++b) edges[b] = all[all.size() * static_cast<std::size_t>(b + 1) / kRemissionBins];
  for (std::size_t f = 0; f < frames.size(); ++f)
    for (float r : remissions[f])
      out[f].remissionBin.push_back(static_cast<std::uint8_t>(std::upper_bound(edges.begin(), edges.end(), r) - edges.begin()));
  return out;
}

std::vector<LevelImage> prepareLevelImages(const cv::Mat& image, int levels, double edgeDecay) {
  if (image.empty() || image.depth() != CV_8U || (image.channels() != 1 && image.channels() != 3))
    throw std::invalid_argument("targetless calibration: images must be 8-bit grey or BGR");
  cv::Mat grey;
  if (image.channels() == 3)
    cv::cvtColor(image, grey, cv::COLOR_BGR2GRAY);
  else
    grey = image;
  cv::Mat equalised;
  cv::equalizeHist(grey, equalised);
  std::vector<LevelImage> out(static_cast<std::size_t>(levels));
  equalised.convertTo(out[0].intensity, CV_32F, kIntensityBins / 256.0);
  for (std::size_t l = 1; l < out.size(); ++l) cv::pyrDown(out[l - 1].intensity, out[l].intensity);
  for (LevelImage& li : out) li.edges = edgeMap(li.intensity, static_cast<float>(edgeDecay));
  return out;
}

AlignmentCost::AlignmentCost(const std::vector<LaserSamples>& laser, const std::vector<std::vector<LevelImage>>& images,
                             const Eigen::Matrix3d& K, int level)
    : laser_(laser), images_(images), level_(level) {
  // Pixel centres at integer coordinates: pyrDown's pixel i sits on the finer level's pixel 2i.
  K_ = K.cast<float>();
  K_.topRows<2>() /= static_cast<float>(1 << level);
}

AlignmentScore AlignmentCost::score(const Eigen::Isometry3d& laserToCamera, const std::vector<bool>& skip,
                                   AlignmentMeasure measure) const {
  const bool wantMi = measure != AlignmentMeasure::kEdges, wantEdges = measure != AlignmentMeasure::kMutualInformation;
  const Eigen::Matrix3f R = laserToCamera.linear().cast<float>();
  const Eigen::Vector3f t = laserToCamera.translation().cast<float>();
  const float fx = K_(0, 0), s = K_(0, 1), cx = K_(0, 2), fy = K_(1, 1), cy = K_(1, 2);
  constexpr float kMinZ = 0.1f;
  std::vector<double> joint(kRemissionBins * kIntensityBins, 0.0);
  double edgeSum = 0, edgeWeight = 0, plainSum = 0;
  std::size_t plainCount = 0;
  AlignmentScore result;
  for (std::size_t f = 0; f < laser_.size(); ++f) {
    if (!skip.empty() && skip[f]) continue;
    const LaserSamples& ls = laser_[f];
    const LevelImage& img = images_[f][static_cast<std::size_t>(level_)];
    for (std::size_t i = 0; wantMi && i < ls.xyz.size(); ++i) {
      const Eigen::Vector3f c = R * ls.xyz[i] + t;
      if (c.z() < kMinZ) continue;
      const float iz = 1.f / c.z();
      float g;
      if (!sample(img.intensity, (fx * c.x() + s * c.y()) * iz + cx, fy * c.y() * iz + cy, g)) continue;
      // Linear (soft) binning of the intensity keeps the measure continuous in the transform.
      const float pos = std::clamp(g - 0.5f, 0.f, static_cast<float>(kIntensityBins - 1));
      const int b0 = std::min(static_cast<int>(pos), kIntensityBins - 2);
      const float a = pos - static_cast<float>(b0);
      double* row = &joint[static_cast<std::size_t>(ls.remissionBin[i]) * kIntensityBins];
      row[b0] += 1 - a;
      row[b0 + 1] += a;
      ++result.points;
    }
    edgeWeight += ls.edgeWeightSum;
    for (std::size_t i = 0; wantEdges && i < ls.edgeXyz.size(); ++i) {
      const Eigen::Vector3f c = R * ls.edgeXyz[i] + t;
      if (c.z() < kMinZ) continue;
      const float iz = 1.f / c.z();
      float e;
      if (sample(img.edges, (fx * c.x() + s * c.y()) * iz + cx, fy * c.y() * iz + cy, e)) edgeSum += ls.edgeWeight[i] * e;
    }
    for (std::size_t i = 0; wantEdges && i < ls.plainXyz.size(); ++i) {
      const Eigen::Vector3f c = R * ls.plainXyz[i] + t;
      if (c.z() < kMinZ) continue;
      const float iz = 1.f / c.z();
      float e;
      if (sample(img.edges, (fx * c.x() + s * c.y()) * iz + cx, fy * c.y() * iz + cy, e)) {
        plainSum += e;
        ++plainCount;
      }
    }
  }
  // Contrast: edge strength under depth edges beyond that under the other points, so that moving
  // everything onto texture (foliage) gains nothing.
  if (edgeWeight > 0 && plainCount > 0) result.edgeAlignment = edgeSum / edgeWeight - plainSum / static_cast<double>(plainCount);
  const double n = static_cast<double>(result.points);
  if (result.points < 100) return result;
  std::vector<double> rem(kRemissionBins, 0.0), inten(kIntensityBins, 0.0);
  for (int r = 0; r < kRemissionBins; ++r)
    for (int g = 0; g < kIntensityBins; ++g) {
      rem[r] += joint[r * kIntensityBins + g];
      inten[g] += joint[r * kIntensityBins + g];
    }
  double mi = 0;
  for (int r = 0; r < kRemissionBins; ++r)
    for (int g = 0; g < kIntensityBins; ++g) {
      const double h = joint[r * kIntensityBins + g];
      if (h > 0) mi += h * std::log(h * n / (rem[r] * inten[g]));
    }
  result.mutualInformation = mi / n;
  return result;
}

}  // namespace fusedet::fusion::detail
