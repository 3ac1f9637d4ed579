// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/grouping.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace fusedet::boosting {

namespace {

struct IRect {
  int x = 0, y = 0, w = 0, h = 0;
};

IRect toInt(const Box& b) {
  return {static_cast<int>(std::lrint(b.x)), static_cast<int>(std::lrint(b.y)), static_cast<int>(std::lrint(b.w)),
          static_cast<int>(std::lrint(b.h))};
}

bool similar(const IRect& a, const IRect& b, double eps) {
  const double delta = eps * (std::min(a.w, b.w) + std::min(a.h, b.h)) * 0.5;
  return std::abs(a.x - b.x) <= delta && std::abs(a.y - b.y) <= delta &&
         std::abs(a.x + a.w - b.x - b.w) <= delta && std::abs(a.y + a.h - b.y - b.h) <= delta;
}

int find(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] = parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

Detection makeDetection(const Box& box, double score, const std::string& className, const LayerStack& stack) {
  Detection d;
  d.className = className;
  d.score = score;
  d.box = box;
  if (stack.width() > 0 && stack.height() > 0) d.unitBox = stack.toUnit(box);
  d.stamp = stack.stamp;
  d.stackId = stack.id;
  return d;
}

std::vector<Detection> groupOpenCv(std::span<const RawHit> hits, const GroupParams& p, const std::string& cls,
                                   const LayerStack& stack, std::vector<HitFate>& fates) {
  std::vector<Detection> out;
  fates.assign(hits.size(), HitFate{});
  if (p.minNeighbors <= 0) {
    for (std::size_t i = 0; i < hits.size(); ++i) {
      fates[i].detection = static_cast<int>(i);
      out.push_back(makeDetection(hits[i].box, 1, cls, stack));
    }
    return out;
  }
  const int n = static_cast<int>(hits.size());
  std::vector<IRect> r(hits.size());
  for (std::size_t i = 0; i < hits.size(); ++i) r[i] = toInt(hits[i].box);
  std::vector<int> parent(hits.size());
  std::iota(parent.begin(), parent.end(), 0);
  // Linked pairs are |x_i - x_j| <= delta <= eps * (w_i + h_i) / 2 apart (min(w) <= w_i), so a
  // sweep over x-sorted boxes finds every pair without testing all n^2 (raw hits of a big image
  // run into the ten thousands). The classes do not depend on the order pairs are found in.
  std::vector<int> byX(hits.size());
  std::iota(byX.begin(), byX.end(), 0);
  std::stable_sort(byX.begin(), byX.end(), [&](int a, int b) { return r[std::size_t(a)].x < r[std::size_t(b)].x; });
  for (std::size_t a = 0; a < byX.size(); ++a) {
    const IRect& ra = r[static_cast<std::size_t>(byX[a])];
    const double reach = std::max(0.0, p.eps) * (std::max(ra.w, 0) + std::max(ra.h, 0)) * 0.5;
    for (std::size_t b = a + 1; b < byX.size(); ++b) {
      const IRect& rb = r[static_cast<std::size_t>(byX[b])];
      if (rb.x - ra.x > reach) break;
      if (similar(ra, rb, p.eps)) {
        const int i = find(parent, byX[a]), j = find(parent, byX[b]);
        if (i != j) parent[static_cast<std::size_t>(std::max(i, j))] = std::min(i, j);
      }
    }
  }
  // Classes numbered by their first member, as cv::partition numbers them.
  std::vector<int> label(hits.size(), -1), rootLabel(hits.size(), -1);
  int classes = 0;
  for (int i = 0; i < n; ++i) {
    const int root = find(parent, i);
    if (rootLabel[static_cast<std::size_t>(root)] < 0) rootLabel[static_cast<std::size_t>(root)] = classes++;
    label[static_cast<std::size_t>(i)] = rootLabel[static_cast<std::size_t>(root)];
  }
  std::vector<std::array<long long, 4>> sums(static_cast<std::size_t>(classes), {0, 0, 0, 0});
  std::vector<int> count(static_cast<std::size_t>(classes), 0);
  for (int i = 0; i < n; ++i) {
    auto& s = sums[static_cast<std::size_t>(label[static_cast<std::size_t>(i)])];
    const IRect& q = r[static_cast<std::size_t>(i)];
    s[0] += q.x, s[1] += q.y, s[2] += q.w, s[3] += q.h;
    ++count[static_cast<std::size_t>(label[static_cast<std::size_t>(i)])];
  }
  // Average in float and round like OpenCV (saturate_cast<int>(sum * (1.f / n))).
  std::vector<IRect> avg(static_cast<std::size_t>(classes));
  for (std::size_t c = 0; c < avg.size(); ++c) {
    const float s = 1.f / static_cast<float>(count[c]);
    auto rnd = [s](long long v) { return static_cast<int>(std::lrintf(static_cast<float>(v) * s)); };
    avg[c] = {rnd(sums[c][0]), rnd(sums[c][1]), rnd(sums[c][2]), rnd(sums[c][3])};
  }
  std::vector<HitFate> classFate(avg.size());
  for (std::size_t i = 0; i < avg.size(); ++i) {
    const IRect& r1 = avg[i];
    const int n1 = count[i];
    classFate[i].groupSize = n1;
    if (n1 <= p.minNeighbors) {
      classFate[i].outcome = HitFate::Outcome::kTooFewNeighbours;
      continue;
    }
    bool inside = false;
    for (std::size_t j = 0; j < avg.size() && !inside; ++j) {
      const int n2 = count[j];
      if (j == i || n2 <= p.minNeighbors) continue;
      const IRect& r2 = avg[j];
      const int dx = static_cast<int>(std::lrint(r2.w * p.eps)), dy = static_cast<int>(std::lrint(r2.h * p.eps));
      inside = r1.x >= r2.x - dx && r1.y >= r2.y - dy && r1.x + r1.w <= r2.x + r2.w + dx &&
               r1.y + r1.h <= r2.y + r2.h + dy && (n2 > std::max(3, n1) || n1 < 3);
    }
    if (inside) {
      classFate[i].outcome = HitFate::Outcome::kInsideBiggerGroup;
      continue;
    }
    classFate[i].detection = static_cast<int>(out.size());
    out.push_back(makeDetection(Box{double(r1.x), double(r1.y), double(r1.w), double(r1.h)}, n1, cls, stack));
  }
  for (std::size_t i = 0; i < hits.size(); ++i) fates[i] = classFate[static_cast<std::size_t>(label[i])];
  return out;
}

}  // namespace

std::vector<Detection> groupHits(std::span<const RawHit> hits, const GroupParams& params, const std::string& className,
                                 const LayerStack& stack, std::vector<HitFate>* fates) {
  std::vector<HitFate> local;
  std::vector<HitFate>& f = fates ? *fates : local;
  return groupOpenCv(hits, params, className, stack, f);
}

std::vector<Detection> detect(const Detector& detector, const LayerStack& stack, const ScanParams& scan,
                              const GroupParams& group) {
  const std::vector<RawHit> hits = detector.scan(stack, scan);
  return groupHits(hits, group, detector.cascade().className, stack);
}

}  // namespace fusedet::boosting
