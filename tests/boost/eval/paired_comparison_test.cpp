// SPDX-License-Identifier: Apache-2.0
// Paired comparisons of two runs (fusedet/boost/paired_comparison.h) and their outcomes.json files
// (fusedet/boost/outcomes_file.h) on small outcomes whose F and AP are worked out by hand in the comments.

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "../random_edits.h"
#include "fusedet/boost/class_rules.h"
#include "fusedet/boost/outcomes_file.h"
#include "fusedet/boost/paired_comparison.h"

namespace fusedet::boosting {
namespace {

FrameOutcome frame(std::size_t positives, std::vector<std::pair<double, bool>> dets) {
  FrameOutcome f;
  f.positives = positives;
  for (const auto& [score, hit] : dets) f.detections.push_back({score, hit});
  return f;
}

OutcomeSet set(const std::string& config, std::vector<FrameOutcome> frames, const std::string& cls = "car") {
  OutcomeSet s;
  s.className = cls;
  s.protocol = "lodo";
  s.folds = 22;
  s.config = config;
  s.rule = matchConfigFor(cls);
  for (std::size_t i = 0; i < frames.size(); ++i) s.frameIds.push_back("drive/" + std::to_string(i));
  s.frames = std::move(frames);
  return s;
}

std::string errorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::exception& e) {
    return e.what();
  }
  return "";
}

// Two frames with one positive each. A: a hit (score 2) and a hit (score 1): R = P = F = 1, AP 1.
// B: a false alarm (score 2) on frame 0, a hit (score 1) on frame 1: R = P = 0.5, F = 0.5; the
// ranking is FA then hit, so precision at every recall <= 0.5 is 0.5 and nothing reaches more:
// AP (40 points) = 20 x 0.5 / 40 = 0.25.
TEST(PairedComparison, HandWorkedFAndAp) {
  const std::vector<FrameOutcome> a{frame(1, {{2, true}}), frame(1, {{1, true}})};
  const std::vector<FrameOutcome> b{frame(1, {{2, false}}), frame(1, {{1, true}})};
  const PairedComparison c = comparePaired(a, b);
  EXPECT_EQ(c.frames, 2u);
  EXPECT_DOUBLE_EQ(*c.f.a, 1.0);
  EXPECT_DOUBLE_EQ(*c.f.b, 0.5);
  EXPECT_DOUBLE_EQ(*c.f.difference, 0.5);
  EXPECT_DOUBLE_EQ(*c.ap.a, 1.0);
  EXPECT_DOUBLE_EQ(*c.ap.b, 0.25);
  EXPECT_DOUBLE_EQ(*c.ap.difference, 0.75);
  EXPECT_EQ(c.countsA.hits, 2u);
  EXPECT_EQ(c.countsB.falseAlarms, 1u);
  EXPECT_EQ(c.countsB.misses, 1u);
  // A resample of frame 1 twice: both F = 1 (difference 0); of frame 0 twice: B has no hit, F_b = 0
  // (difference 1); the mixed draws give 0.5. So every difference lies in [0, 1] and some are 0.
  ASSERT_TRUE(c.f.interval);
  EXPECT_GE(c.f.interval->lo, 0.0);
  EXPECT_LE(c.f.interval->hi, 1.0);
  EXPECT_EQ(c.f.verdict, "not shown");
}

// 60 frames with one positive each. Both hit frames 0-29 and miss 30-59, except that A also hits
// frames 30-37: F_a = 2 x (38/60) / (1 + 38/60) = 76/98, F_b = 2 x 0.5 / 1.5 = 2/3 (no false
// alarms: precision 1). A resample without any of A's 8 extra frames has probability (52/60)^60
// ~ 2e-4, far below the 2.5 % quantile, so the paired interval lies above 0: "holds". Resampled
// alone, each F varies with how many of the 30 easy frames are drawn, and the two unpaired
// intervals overlap - the case this tool exists for.
TEST(PairedComparison, KnownDifferenceExcludesZeroWhereUnpairedIntervalsOverlap) {
  std::vector<FrameOutcome> a, b;
  for (int i = 0; i < 60; ++i) {
    a.push_back(i < 38 ? frame(1, {{1, true}}) : frame(1, {}));
    b.push_back(i < 30 ? frame(1, {{1, true}}) : frame(1, {}));
  }
  const PairedComparison c = comparePaired(a, b);
  EXPECT_DOUBLE_EQ(*c.f.a, 76.0 / 98.0);
  EXPECT_DOUBLE_EQ(*c.f.b, 2.0 / 3.0);
  EXPECT_NEAR(*c.f.difference, 76.0 / 98.0 - 2.0 / 3.0, 1e-12);
  ASSERT_TRUE(c.f.interval);
  EXPECT_GT(c.f.interval->lo, 0.0);
  EXPECT_LT(c.f.interval->lo, *c.f.difference);
  EXPECT_GT(c.f.interval->hi, *c.f.difference);
  EXPECT_EQ(c.f.verdict, "holds");
  // The other way round it is contradicted, with the mirrored interval.
  const PairedComparison r = comparePaired(b, a);
  EXPECT_EQ(r.f.verdict, "contradicted");
  EXPECT_NEAR(r.f.interval->hi, -c.f.interval->lo, 1e-9);

  std::vector<std::size_t> all(60);
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  const auto alone = [](const std::vector<FrameOutcome>& f) {
    return *bootstrapInterval(f.size(), [&](const std::vector<std::size_t>& idx) { return fMeasureOf(f, idx); });
  };
  EXPECT_LT(alone(a).lo, alone(b).hi) << "unpaired intervals should overlap here";
}

TEST(PairedComparison, IdenticalRunsGiveZeroIntervalNotShown) {
  std::vector<FrameOutcome> a;
  for (int i = 0; i < 30; ++i) a.push_back(frame(2, {{double(i % 7), i % 3 == 0}, {0.5, false}}));
  const OutcomeSet x = set("all", a), y = set("all", a);
  const PairedComparison c = compareSets(x, y);
  EXPECT_EQ(*c.f.a, *c.f.b);
  EXPECT_EQ(*c.f.difference, 0.0);
  ASSERT_TRUE(c.f.interval);
  EXPECT_EQ(c.f.interval->lo, 0.0);
  EXPECT_EQ(c.f.interval->hi, 0.0);
  EXPECT_EQ(c.f.verdict, "not shown");
  EXPECT_EQ(c.ap.interval->lo, 0.0);
  EXPECT_EQ(c.ap.interval->hi, 0.0);
  EXPECT_EQ(c.ap.verdict, "not shown");
}

TEST(PairedComparison, FramesAreMatchedByNameNotByPosition) {
  const OutcomeSet a = set("all", {frame(1, {{1, true}}), frame(1, {}), frame(2, {{3, false}})});
  OutcomeSet shuffled = a;
  std::swap(shuffled.frameIds[0], shuffled.frameIds[2]);
  std::swap(shuffled.frames[0], shuffled.frames[2]);
  const PairedComparison c = compareSets(a, shuffled);
  EXPECT_EQ(*c.f.difference, 0.0);
  EXPECT_EQ(c.f.interval->lo, 0.0);
  EXPECT_EQ(c.f.interval->hi, 0.0);
}

TEST(PairedComparison, RefusesOtherFramesClassesAndRules) {
  const OutcomeSet a = set("all", {frame(1, {{1, true}}), frame(1, {}), frame(1, {})});
  OutcomeSet renamed = a;
  renamed.frameIds[1] = "other/7";
  const std::string frames = errorOf([&] { compareSets(a, renamed); });
  EXPECT_NE(frames.find("car / lodo / all against car / lodo / all: the runs tested different frames (3 against 3; "
                        "1 only in the first: drive/1; 1 only in the second: other/7)"),
            std::string::npos)
      << frames;
  OutcomeSet fewer = a;
  fewer.frameIds.pop_back();
  fewer.frames.pop_back();
  EXPECT_NE(errorOf([&] { compareSets(a, fewer); }).find("(3 against 2; 1 only in the first: drive/2)"),
            std::string::npos);

  // --min-iou 0.5 against the devkit's 0.7 for car: another rule.
  OutcomeSet pascal = a;
  pascal.rule = matchConfigFor("car", VanPolicy::kIgnore, 0.5);
  const std::string rule = errorOf([&] { compareSets(pascal, a); });
  EXPECT_NE(rule.find("the runs match detections by different rules (hit overlap (IoU) 0.5 against 0.7)"),
            std::string::npos)
      << rule;
  OutcomeSet vanPositive = a;
  vanPositive.rule = matchConfigFor("car", VanPolicy::kPositive);
  EXPECT_NE(errorOf([&] { compareSets(a, vanPositive); }).find("alias classes [] against [van]"), std::string::npos)
      << errorOf([&] { compareSets(a, vanPositive); });

  OutcomeSet person = set("all", a.frames, "person");
  EXPECT_NE(errorOf([&] { compareSets(a, person); }).find("different classes"), std::string::npos);
  EXPECT_THROW(compareSets(a, person), ComparisonError);
  EXPECT_THROW(comparePaired(a.frames, fewer.frames), std::invalid_argument);
}

TEST(PairedComparison, RunsPairTheirSetsAndFilter) {
  RunOutcomes a, b;
  const std::vector<FrameOutcome> f{frame(1, {{1, true}}), frame(1, {})};
  a.sets = {set("all", f), set("laser", f), set("all", f, "person")};
  b.sets = {set("all", f, "person"), set("all", f)};
  const std::vector<ComparisonRow> rows = compareRuns(a, b, {});
  ASSERT_EQ(rows.size(), 2u);  // laser is only in a
  EXPECT_EQ(rows[0].className, "car");
  EXPECT_EQ(rows[1].className, "person");
  EXPECT_EQ(compareRuns(a, b, {"person", "", "", "", ""}).size(), 1u);
  EXPECT_EQ(compareRuns(a, b, {"", "lodo", "all", "", ""}).size(), 2u);
  // Another configuration of b (e.g. a learning-curve point of the same run): a's laser against b's all.
  const std::vector<ComparisonRow> cross = compareRuns(a, b, {"car", "", "laser", "all", ""});
  ASSERT_EQ(cross.size(), 1u);
  EXPECT_EQ(cross[0].config, "laser");
  EXPECT_EQ(cross[0].configB, "all");
  EXPECT_EQ(rows[0].configB, "all");
  EXPECT_THROW(compareRuns(a, b, {"car", "", "", "all", ""}), std::invalid_argument);
  const std::string none = errorOf([&] { compareRuns(a, b, {"", "3fold", "", "", ""}); });
  EXPECT_NE(none.find("no class / protocol / configuration matching protocol 3fold is in both runs (first: car / "
                      "lodo / all, car / lodo / laser, person / lodo / all; second: person / lodo / all, car / lodo / "
                      "all)"),
            std::string::npos)
      << none;
}

// --protocol-b: a set of one fold design against b's of another on the same frames (a learning
// curve's 3-fold point against leave-one-drive-out), with the difference worked by hand.
TEST(PairedComparison, RunsPairAnotherProtocolOfTheSameFrames) {
  RunOutcomes lodo, three;
  lodo.sets = {set("all", {frame(1, {{2, true}}), frame(1, {{1, true}})})};
  OutcomeSet s = set("all:positives=all", {frame(1, {{2, false}}), frame(1, {{1, true}})});
  s.protocol = "3fold";
  s.folds = 3;
  three.sets = {s, set("all", {frame(1, {}), frame(1, {})})};  // a lodo set too: not the one asked for
  const std::vector<ComparisonRow> rows = compareRuns(lodo, three, {"car", "lodo", "all", "all:positives=all", "3fold"});
  ASSERT_EQ(rows.size(), 1u);
  EXPECT_EQ(rows[0].protocol, "lodo");
  EXPECT_EQ(rows[0].protocolB, "3fold");
  EXPECT_EQ(rows[0].configB, "all:positives=all");
  EXPECT_DOUBLE_EQ(*rows[0].result.f.a, 1.0);
  EXPECT_DOUBLE_EQ(*rows[0].result.f.b, 0.5);  // 1 hit, 1 false alarm, 1 miss: 2 / (2 + 2)
  EXPECT_DOUBLE_EQ(*rows[0].result.f.difference, 0.5);
  // Without it the same filter pairs a's lodo set with b's lodo set of that name (there is none).
  const std::vector<ComparisonRow> same = compareRuns(lodo, three, {"car", "lodo", "all", "", ""});
  ASSERT_EQ(same.size(), 1u);
  EXPECT_EQ(same[0].protocolB, "lodo");
  EXPECT_DOUBLE_EQ(*same[0].result.f.b, 0.0);
  EXPECT_THROW(compareRuns(lodo, three, {"car", "", "all", "", "3fold"}), std::invalid_argument);
  const std::string none = errorOf([&] { compareRuns(lodo, three, {"car", "lodo", "laser", "", "3fold"}); });
  EXPECT_NE(none.find("matching class car protocol lodo config laser against protocol 3fold"), std::string::npos) << none;
}

TEST(OutcomesFile, RoundTripsExactly) {
  RunOutcomes run;
  run.command = "fusedet experiments --classes car \"quoted\"";
  OutcomeSet s = set("and", {frame(3, {{0.1 + 0.2, true}, {1e-300, false}, {-3.5, true}}), frame(0, {}),
                             frame(1, {{7, false}})});
  s.protocol = "3fold";
  s.folds = 3;
  s.rule = matchConfigFor("car", VanPolicy::kPositive, 0.55);
  run.sets = {s, set("hog", {frame(1, {})}, "person")};
  const std::string text = outcomesToText(run);
  const RunOutcomes back = outcomesFromText(text, "x.json");
  EXPECT_EQ(back.command, run.command);
  ASSERT_EQ(back.sets.size(), 2u);
  const OutcomeSet& t = back.sets[0];
  EXPECT_EQ(t.className, "car");
  EXPECT_EQ(t.protocol, "3fold");
  EXPECT_EQ(t.folds, 3u);
  EXPECT_EQ(t.config, "and");
  EXPECT_EQ(t.frameIds, s.frameIds);
  EXPECT_EQ(t.rule.minIou, 0.55);
  EXPECT_EQ(t.rule.aliasClasses, std::vector<std::string>{"van"});
  ASSERT_EQ(t.frames.size(), 3u);
  EXPECT_EQ(t.frames[0].positives, 3u);
  EXPECT_EQ(t.frames[0].detections[0].score, 0.1 + 0.2);  // bit for bit
  EXPECT_EQ(t.frames[0].detections[1].score, 1e-300);
  EXPECT_FALSE(t.frames[0].detections[1].hit);
  EXPECT_EQ(t.frames[0].detections[2].score, -3.5);
  EXPECT_EQ(outcomesToText(back), text);
  EXPECT_NO_THROW(compareSets(s, t));
  EXPECT_EQ(protocolName(22, 22), "lodo");
  EXPECT_EQ(protocolName(3, 22), "3fold");
}

std::string sampleText() {
  RunOutcomes run;
  run.command = "fusedet experiments";
  run.sets = {set("all", {frame(2, {{3, true}, {1, false}}), frame(0, {{2, false}}), frame(1, {})}),
              set("laser", {frame(1, {{1, true}})})};
  return outcomesToText(run);
}

std::string replaced(std::string s, const std::string& from, const std::string& to) {
  const auto p = s.find(from);
  EXPECT_NE(p, std::string::npos) << from;
  return p == std::string::npos ? s : s.replace(p, from.size(), to);
}

TEST(OutcomesFile, BrokenFilesAreClearErrors) {
  const std::string good = sampleText();
  const auto err = [](const std::string& text) { return errorOf([&] { outcomesFromText(text, "o.json"); }); };
  EXPECT_NE(err("").find("o.json: line 1, column 1: not valid JSON"), std::string::npos) << err("");
  EXPECT_NE(err("[1]").find("o.json: expected a JSON object, got array"), std::string::npos);
  EXPECT_NE(err(replaced(good, "fusedet-outcomes", "fusedet-cascade")).find("o.json: format: 'fusedet-cascade' is not"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "\"version\": 1", "\"version\": 2")).find("unsupported version 2 (this build reads 1)"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "\"positives\": 2", "\"positives\": 0"))
                .find("o.json: sets[0].frames[0]: 1 hits but only 0 positives"),
            std::string::npos)
      << err(replaced(good, "\"positives\": 2", "\"positives\": 0"));
  EXPECT_NE(err(replaced(good, "\"positives\": 2", "\"positives\": -2"))
                .find("sets[0].frames[0].positives: expected a count (integer >= 0), got -2"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "[3.0,1]", "[3,2]")).find("sets[0].frames[0].detections[0][1]: 2 is out of range"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "[3.0,1]", "[3]")).find("detections[0]: expected [score, hit (1) or false alarm (0)]"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "[3.0,1]", "[1e999,1]")).find("o.json"), std::string::npos);
  EXPECT_NE(err(replaced(good, "\"drive/1\"", "\"drive/0\"")).find("sets[0].frames[1]: frame 'drive/0' appears twice"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "\"config\": \"laser\"", "\"config\": \"all\""))
                .find("sets[1]: car / lodo / all appears twice"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "\"min_iou\":0.7", "\"min_iou\":\"0.7\""))
                .find("sets[0].rule.min_iou: expected a number, got string"),
            std::string::npos);
  EXPECT_NE(err(replaced(good, "\"protocol\"", "\"Protocol\"")).find("sets[0]: missing \"protocol\""),
            std::string::npos);
}

// Every truncation of a valid file and thousands of random edits: parsed or a clear error naming
// the file, never a crash or another exception type.
TEST(OutcomesFile, TruncatedAndFuzzedFilesNeverCrash) {
  const std::string good = sampleText();
  for (std::size_t n = 0; n + 1 < good.size(); ++n) {
    // A cut inside the file leaves unbalanced brackets: always an error ("\n" at the end is optional).
    const std::string cut = good.substr(0, n);
    if (cut.find_last_not_of('\n') == good.find_last_not_of('\n')) continue;
    const std::string e = errorOf([&] { outcomesFromText(cut, "cut.json"); });
    EXPECT_EQ(e.rfind("cut.json: ", 0), 0u) << n << ": " << e;
  }
  std::mt19937 rng(15);
  int parsed = 0, rejected = 0;
  for (int it = 0; it < 3000; ++it) {
    const std::string s = fuzz::randomlyEdited(good, rng, "{}[],:\"0-e9.1");
    try {
      const RunOutcomes r = outcomesFromText(s, "fuzz.json");
      for (const OutcomeSet& x : r.sets) compareSets(x, x);  // what parses can be compared
      ++parsed;
    } catch (const OutcomesError& e) {
      EXPECT_EQ(std::string(e.what()).rfind("fuzz.json: ", 0), 0u) << e.what();
      ++rejected;
    }
  }
  EXPECT_GT(rejected, 2000);
  EXPECT_EQ(parsed + rejected, 3000);
}

TEST(OutcomesFile, MissingFileSaysWhereItComesFrom) {
  const std::string e = errorOf([] { readOutcomes("/nonexistent/run"); });
  EXPECT_NE(e.find("/nonexistent/run: cannot open (no such file; a `fusedet experiments` run writes it beside "
                   "results.json)"),
            std::string::npos)
      << e;
}

}  // namespace
}  // namespace fusedet::boosting
