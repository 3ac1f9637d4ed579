// SPDX-License-Identifier: Apache-2.0
// CLEAR MOT and HOTA of the tracking library against worked examples and against an independent
// implementation written here from the papers' definitions (brute-force matching, no code shared
// with the library), on random sequences.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>

#include "fusedet/tracking/clear_mot.h"
#include "fusedet/tracking/hota.h"

using namespace fusedet;
using namespace fusedet::tracking;

namespace {

MotObject obj(std::int64_t id, double x, double y, double w, double h) { return MotObject{id, Box{x, y, w, h}}; }

// ---- the independent implementation ----

double overlap(const Box& a, const Box& b) {
  const double ix = std::max(0.0, std::min(a.x + a.w, b.x + b.w) - std::max(a.x, b.x));
  const double iy = std::max(0.0, std::min(a.y + a.h, b.y + b.h) - std::max(a.y, b.y));
  const double inter = ix * iy, uni = a.w * a.h + b.w * b.h - inter;
  return uni > 0 ? inter / uni : 0;
}

// Best matching by trying every one: maximises the summed score over pairs with score > 0.
void tryAll(const std::vector<std::vector<double>>& score, std::size_t row, std::vector<int>& cur, std::vector<char>& used,
            double sum, double& best, std::vector<int>& bestMatch) {
  if (row == score.size()) {
    if (sum > best + 1e-12) {
      best = sum;
      bestMatch = cur;
    }
    return;
  }
  cur[row] = -1;
  tryAll(score, row + 1, cur, used, sum, best, bestMatch);
  for (std::size_t j = 0; j < used.size(); ++j) {
    if (used[j] || score[row][j] <= 0) continue;
    used[j] = 1;
    cur[row] = static_cast<int>(j);
    tryAll(score, row + 1, cur, used, sum + score[row][j], best, bestMatch);
    used[j] = 0;
  }
  cur[row] = -1;
}
std::vector<int> bestMatching(const std::vector<std::vector<double>>& score, std::size_t cols) {
  std::vector<int> cur(score.size(), -1), best(score.size(), -1);
  std::vector<char> used(cols, 0);
  double bestSum = 0;
  tryAll(score, 0, cur, used, 0, bestSum, best);
  return best;
}

// One frame's matching: IoU >= 0.5 pairs, a pair kept from the previous frame preferred.
std::vector<int> matchFrame(const MotFrame& f, const std::map<std::int64_t, std::int64_t>& prevFrameMatch) {
  std::vector<std::vector<double>> score(f.truth.size(), std::vector<double>(f.hypotheses.size(), 0));
  for (std::size_t i = 0; i < f.truth.size(); ++i)
    for (std::size_t j = 0; j < f.hypotheses.size(); ++j) {
      const double s = overlap(f.truth[i].box, f.hypotheses[j].box);
      if (s < 0.5) continue;
      const auto p = prevFrameMatch.find(f.truth[i].id);
      score[i][j] = s + (p != prevFrameMatch.end() && p->second == f.hypotheses[j].id ? 1000 : 0);
    }
  return bestMatching(score, f.hypotheses.size());
}

struct RefClear {
  double tp = 0, fn = 0, fp = 0, idsw = 0, iou = 0;
};

RefClear referenceClear(const MotSequence& seq) {
  RefClear r;
  std::map<std::int64_t, std::int64_t> lastMatch, prevFrameMatch;
  for (const MotFrame& f : seq) {
    const std::vector<int> m = matchFrame(f, prevFrameMatch);
    std::map<std::int64_t, std::int64_t> now;
    double matched = 0;
    for (std::size_t i = 0; i < f.truth.size(); ++i) {
      const std::int64_t g = f.truth[i].id;
      if (m[i] < 0) continue;
      const std::int64_t h = f.hypotheses[static_cast<std::size_t>(m[i])].id;
      matched += 1;
      r.iou += overlap(f.truth[i].box, f.hypotheses[static_cast<std::size_t>(m[i])].box);
      if (lastMatch.count(g) && lastMatch[g] != h) r.idsw += 1;
      lastMatch[g] = h;
      now[g] = h;
    }
    prevFrameMatch = now;
    r.tp += matched;
    r.fn += static_cast<double>(f.truth.size()) - matched;
    r.fp += static_cast<double>(f.hypotheses.size()) - matched;
  }
  return r;
}

// Fragmentations from the frame-indexed timeline (absent frames interrupt).
double referenceFrag(const MotSequence& seq) {
  // Re-run the matching per frame and record, per truth id, the frames where it was matched.
  std::map<std::int64_t, std::vector<int>> matchedFrames;
  std::map<std::int64_t, std::int64_t> prevFrameMatch;
  for (std::size_t k = 0; k < seq.size(); ++k) {
    const MotFrame& f = seq[k];
    const std::vector<int> m = matchFrame(f, prevFrameMatch);
    prevFrameMatch.clear();
    for (std::size_t i = 0; i < f.truth.size(); ++i)
      if (m[i] >= 0) {
        matchedFrames[f.truth[i].id].push_back(static_cast<int>(k));
        prevFrameMatch[f.truth[i].id] = f.hypotheses[static_cast<std::size_t>(m[i])].id;
      }
  }
  double frag = 0;
  for (const auto& [g, frames] : matchedFrames)
    for (std::size_t k = 1; k < frames.size(); ++k) frag += frames[k] != frames[k - 1] + 1;
  return frag;
}

struct RefHota {
  double hota = 0, detA = 0, assA = 0;
};

RefHota referenceHota(const MotSequence& seq) {
  std::map<std::int64_t, double> nG, nH;
  std::map<std::pair<std::int64_t, std::int64_t>, double> pot;
  for (const MotFrame& f : seq) {
    for (const auto& g : f.truth) nG[g.id] += 1;
    for (const auto& h : f.hypotheses) nH[h.id] += 1;
    for (std::size_t i = 0; i < f.truth.size(); ++i)
      for (std::size_t j = 0; j < f.hypotheses.size(); ++j) {
        double rowSum = 0, colSum = 0;
        for (const auto& h : f.hypotheses) rowSum += overlap(f.truth[i].box, h.box);
        for (const auto& g : f.truth) colSum += overlap(g.box, f.hypotheses[j].box);
        const double s = overlap(f.truth[i].box, f.hypotheses[j].box);
        if (s > 0) pot[{f.truth[i].id, f.hypotheses[j].id}] += s / (rowSum + colSum - s);
      }
  }
  RefHota out;
  for (int a = 1; a <= 19; ++a) {
    const double alpha = 0.05 * a;
    double tp = 0, fn = 0, fp = 0;
    std::map<std::pair<std::int64_t, std::int64_t>, double> tpa;
    for (const MotFrame& f : seq) {
      std::vector<std::vector<double>> score(f.truth.size(), std::vector<double>(f.hypotheses.size(), 0));
      for (std::size_t i = 0; i < f.truth.size(); ++i)
        for (std::size_t j = 0; j < f.hypotheses.size(); ++j) {
          const auto key = std::make_pair(f.truth[i].id, f.hypotheses[j].id);
          const double p = pot.count(key) ? pot[key] : 0;
          score[i][j] = p / (nG[key.first] + nH[key.second] - p) * overlap(f.truth[i].box, f.hypotheses[j].box);
        }
      const std::vector<int> m = bestMatching(score, f.hypotheses.size());
      double n = 0;
      for (std::size_t i = 0; i < f.truth.size(); ++i) {
        if (m[i] < 0) continue;
        const MotObject& h = f.hypotheses[static_cast<std::size_t>(m[i])];
        if (overlap(f.truth[i].box, h.box) + 1e-15 < alpha) continue;
        n += 1;
        tpa[{f.truth[i].id, h.id}] += 1;
      }
      tp += n;
      fn += static_cast<double>(f.truth.size()) - n;
      fp += static_cast<double>(f.hypotheses.size()) - n;
    }
    double ass = 0;
    for (const auto& [key, c] : tpa) ass += c * c / (nG[key.first] + nH[key.second] - c);
    const double assA = tp > 0 ? ass / tp : 0;
    const double detA = tp + fn + fp > 0 ? tp / (tp + fn + fp) : 0;
    out.detA += detA / 19;
    out.assA += assA / 19;
    out.hota += std::sqrt(detA * assA) / 19;
  }
  return out;
}

MotSequence randomSequence(std::mt19937& rng) {
  std::uniform_real_distribution<double> pos(0, 60), jitter(-4, 4), size(10, 30);
  std::bernoulli_distribution present(0.8), detected(0.8), swap(0.15), clutter(0.3);
  const int truths = std::uniform_int_distribution<int>(1, 3)(rng);
  std::vector<Box> boxes;
  std::vector<std::int64_t> hypIdOf;
  for (int g = 0; g < truths; ++g) {
    boxes.push_back(Box{pos(rng), pos(rng), size(rng), size(rng)});
    hypIdOf.push_back(100 + g);
  }
  std::int64_t nextHyp = 200;
  MotSequence seq(static_cast<std::size_t>(std::uniform_int_distribution<int>(1, 8)(rng)));
  for (MotFrame& f : seq) {
    for (int g = 0; g < truths; ++g) {
      Box& b = boxes[static_cast<std::size_t>(g)];
      b.x += jitter(rng) / 2;
      b.y += jitter(rng) / 2;
      if (!present(rng)) continue;
      f.truth.push_back(MotObject{g + 1, b});
      if (!detected(rng)) continue;
      if (swap(rng)) hypIdOf[static_cast<std::size_t>(g)] = nextHyp++;
      f.hypotheses.push_back(MotObject{hypIdOf[static_cast<std::size_t>(g)], Box{b.x + jitter(rng), b.y + jitter(rng), b.w + jitter(rng), b.h + jitter(rng)}});
    }
    if (clutter(rng)) f.hypotheses.push_back(MotObject{nextHyp++, Box{pos(rng), pos(rng), size(rng), size(rng)}});
  }
  return seq;
}

}  // namespace

TEST(ClearMot, WorkedExample) {
  // Truth 1 in 4 frames; hypothesis 10, then 11 (a switch), a miss (a fragmentation when 11
  // comes back), and a false positive far away in the last frame.
  MotSequence seq(4);
  for (MotFrame& f : seq) f.truth.push_back(obj(1, 0, 0, 10, 10));
  seq[0].hypotheses.push_back(obj(10, 0, 0, 10, 10));
  seq[1].hypotheses.push_back(obj(11, 0, 0, 10, 10));
  seq[3].hypotheses.push_back(obj(11, 0, 0, 10, 8));  // IoU 0.8
  seq[3].hypotheses.push_back(obj(12, 50, 50, 10, 10));
  const ClearMot r = clearMot(seq);
  EXPECT_EQ(r.truth, 4u);
  EXPECT_EQ(r.matches, 3u);
  EXPECT_EQ(r.misses, 1u);
  EXPECT_EQ(r.falsePositives, 1u);
  EXPECT_EQ(r.idSwitches, 1u);
  EXPECT_EQ(r.fragmentations, 1u);
  EXPECT_DOUBLE_EQ(r.mota(), 1 - 3.0 / 4);
  EXPECT_NEAR(r.motp(), (1 + 1 + 0.8) / 3, 1e-12);
  EXPECT_EQ(r.trajectories, 1u);
  EXPECT_EQ(r.partiallyTracked, 1u);  // 3 of 4 frames = 75 %
}

TEST(ClearMot, ContinuingMatchWinsOverABetterOverlap) {
  // Frame 1: truth 1 <-> hyp 10. Frame 2: hyp 11 overlaps better, hyp 10 still above 0.5: 10 stays.
  MotSequence seq(2);
  seq[0].truth = {obj(1, 0, 0, 10, 10)};
  seq[0].hypotheses = {obj(10, 0, 0, 10, 10)};
  seq[1].truth = {obj(1, 0, 0, 10, 10)};
  seq[1].hypotheses = {obj(10, 0, 0, 10, 6), obj(11, 0, 0, 10, 10)};
  const ClearMot r = clearMot(seq);
  EXPECT_EQ(r.idSwitches, 0u);
  EXPECT_EQ(r.falsePositives, 1u);
  EXPECT_NEAR(r.motp(), (1 + 0.6) / 2, 1e-12);
}

TEST(Hota, WorkedExampleIdChangeHalvesAssociation) {
  // One truth in 4 frames, perfectly localised, by hypothesis 10 twice and then 11 twice:
  // DetA = 1; each pair has TPA 2, FNA 2, FPA 0 -> AssA = 0.5; HOTA = sqrt(0.5).
  MotSequence seq(4);
  for (std::size_t k = 0; k < 4; ++k) {
    seq[k].truth = {obj(1, 0, 0, 10, 10)};
    seq[k].hypotheses = {obj(k < 2 ? 10 : 11, 0, 0, 10, 10)};
  }
  const Hota h = hota(seq);
  EXPECT_NEAR(h.meanDetA(), 1, 1e-12);
  EXPECT_NEAR(h.meanAssA(), 0.5, 1e-12);
  EXPECT_NEAR(h.meanHota(), std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(h.meanLocA(), 1, 1e-12);
}

TEST(Hota, WorkedExampleLocalisationThresholds) {
  // IoU 0.625: a TP at alpha 0.05 .. 0.60 (12 thresholds), a FN + FP at 0.65 .. 0.95 (7).
  MotSequence seq(1);
  seq[0].truth = {obj(1, 0, 0, 10, 10)};
  seq[0].hypotheses = {obj(5, 0, 0, 10, 6.25)};
  const Hota h = hota(seq);
  EXPECT_NEAR(h.meanHota(), 12.0 / 19, 1e-12);
  EXPECT_NEAR(h.detA[11], 1, 1e-12);
  EXPECT_NEAR(h.detA[12], 0, 1e-12);
  EXPECT_NEAR(h.locA[0], 0.625, 1e-12);
}

TEST(Hota, EmptyCases) {
  MotSequence onlyTruth(2), onlyHyp(2);
  onlyTruth[0].truth = {obj(1, 0, 0, 5, 5)};
  onlyHyp[1].hypotheses = {obj(1, 0, 0, 5, 5)};
  EXPECT_EQ(hota(onlyTruth).meanHota(), 0);
  EXPECT_EQ(hota(onlyHyp).meanHota(), 0);
  EXPECT_EQ(hota({}).meanHota(), 0);
  EXPECT_EQ(clearMot(onlyHyp).falsePositives, 1u);
  EXPECT_EQ(clearMot(onlyTruth).misses, 1u);
}

TEST(MotMetrics, AgreeWithTheIndependentImplementationOnRandomSequences) {
  std::mt19937 rng(2021);
  for (int trial = 0; trial < 400; ++trial) {
    const MotSequence seq = randomSequence(rng);
    const ClearMot c = clearMot(seq);
    const RefClear rc = referenceClear(seq);
    ASSERT_EQ(static_cast<double>(c.matches), rc.tp) << trial;
    ASSERT_EQ(static_cast<double>(c.misses), rc.fn) << trial;
    ASSERT_EQ(static_cast<double>(c.falsePositives), rc.fp) << trial;
    ASSERT_EQ(static_cast<double>(c.idSwitches), rc.idsw) << trial;
    ASSERT_EQ(static_cast<double>(c.fragmentations), referenceFrag(seq)) << trial;
    ASSERT_NEAR(c.iouSum, rc.iou, 1e-9) << trial;
    const Hota h = hota(seq);
    const RefHota rh = referenceHota(seq);
    ASSERT_NEAR(h.meanHota(), rh.hota, 1e-9) << trial;
    ASSERT_NEAR(h.meanDetA(), rh.detA, 1e-9) << trial;
    ASSERT_NEAR(h.meanAssA(), rh.assA, 1e-9) << trial;
  }
}
