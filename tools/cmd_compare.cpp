// SPDX-License-Identifier: Apache-2.0
// fusedet compare: two `fusedet experiments` runs (an option against the default) judged on the
// same frames with paired bootstrap intervals of F and AP. The rules are in
// fusedet/boost/paired_comparison.h and fusedet/boost/outcomes_file.h; this parses and prints.

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>

#include "command.h"
#include "fusedet/boost/outcomes_file.h"
#include "fusedet/boost/paired_comparison.h"

namespace fusedet::tools {
namespace {
namespace fs = std::filesystem;

struct CompareOptions {
  fs::path a, b;
  boosting::ComparisonFilter filter;
  std::size_t resamples = 1000;
  std::uint64_t seed = 1;
  bool json = false;
};

std::string fixed(const std::optional<double>& v, bool sign = false) {
  if (!v) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, sign ? "%+.3f" : "%.3f", *v + 0.0);  // + 0.0: no "-0.000"
  return buf;
}
std::string interval(const std::optional<boosting::Interval>& i) {
  if (!i) return "[null]";
  return "[" + fixed(i->lo, true) + ", " + fixed(i->hi, true) + "]";
}
nlohmann::json orNull(const std::optional<double>& v) { return v ? nlohmann::json(*v) : nlohmann::json(nullptr); }
nlohmann::json measureJson(const boosting::PairedMeasure& m) {
  nlohmann::json j{{"a", orNull(m.a)}, {"b", orNull(m.b)}, {"difference", orNull(m.difference)},
                   {"interval", nullptr}, {"verdict", m.verdict}};
  if (m.interval) j["interval"] = {{"lo", m.interval->lo}, {"hi", m.interval->hi}, {"resamples", m.interval->resamples}};
  return j;
}
nlohmann::json countsJson(const boosting::Counts& c) {
  return {{"hits", c.hits}, {"false_alarms", c.falseAlarms}, {"misses", c.misses}, {"positives", c.positives}};
}

// "all", or "all:drives=8/all:drives=4" when B's configuration is another; the protocol alike
// ("3fold/lodo").
std::string configLabel(const boosting::ComparisonRow& r) {
  return r.config == r.configB ? r.config : r.config + "/" + r.configB;
}
std::string protocolLabel(const boosting::ComparisonRow& r) {
  return r.protocol == r.protocolB ? r.protocol : r.protocol + "/" + r.protocolB;
}

int runCompare(const CompareOptions& o) {
  const boosting::RunOutcomes a = boosting::readOutcomes(o.a), b = boosting::readOutcomes(o.b);
  boosting::BootstrapConfig boot;
  boot.resamples = o.resamples;
  boot.seed = o.seed;
  const std::vector<boosting::ComparisonRow> rows = boosting::compareRuns(a, b, o.filter, boot);

  if (o.json) {
    nlohmann::ordered_json j;
    j["a"] = {{"path", o.a.string()}, {"command", a.command}};
    j["b"] = {{"path", o.b.string()}, {"command", b.command}};
    j["bootstrap"] = {{"resamples", o.resamples}, {"seed", o.seed}, {"level", boot.level}};
    j["rows"] = nlohmann::json::array();
    for (const auto& r : rows)
      j["rows"].push_back({{"class", r.className},
                           {"protocol", r.protocol},
                           {"config", r.config},
                           {"config_b", r.configB},
                           {"protocol_b", r.protocolB},
                           {"frames", r.result.frames},
                           {"counts_a", countsJson(r.result.countsA)},
                           {"counts_b", countsJson(r.result.countsB)},
                           {"f_measure", measureJson(r.result.f)},
                           {"average_precision", measureJson(r.result.ap)}});
    std::printf("%s\n", j.dump(1).c_str());
    return 0;
  }

  std::printf("compare: A %s: %s\n", o.a.c_str(), a.command.c_str());
  std::printf("compare: B %s: %s\n", o.b.c_str(), b.command.c_str());
  int width = 11;  // the config column fits the longest label (learning-curve pairs are long)
  int pwidth = 8;   // the protocol column alike
  for (const auto& r : rows) {
    width = std::max(width, static_cast<int>(configLabel(r).size()));
    pwidth = std::max(pwidth, static_cast<int>(protocolLabel(r).size()));
  }
  std::printf("%-7s %-*s %-*s %6s %6s %6s %7s %-18s %-12s %6s %6s %7s %-18s %-12s %s\n", "class", pwidth, "protocol", width, "config",
              "frames", "F_a", "F_b", "F_a-F_b", "[95 % CI]", "verdict", "AP_a", "AP_b", "AP_a-b", "[95 % CI]",
              "verdict", "hits/FA/misses a; b");
  for (const auto& r : rows) {
    const auto& c = r.result;
    std::printf("%-7s %-*s %-*s %6zu %6s %6s %7s %-18s %-12s %6s %6s %7s %-18s %-12s %zu/%zu/%zu; %zu/%zu/%zu\n",
                r.className.c_str(), pwidth, protocolLabel(r).c_str(), width, configLabel(r).c_str(), c.frames, fixed(c.f.a).c_str(),
                fixed(c.f.b).c_str(), fixed(c.f.difference, true).c_str(), interval(c.f.interval).c_str(),
                c.f.verdict.c_str(), fixed(c.ap.a).c_str(), fixed(c.ap.b).c_str(),
                fixed(c.ap.difference, true).c_str(), interval(c.ap.interval).c_str(), c.ap.verdict.c_str(),
                c.countsA.hits, c.countsA.falseAlarms, c.countsA.misses, c.countsB.hits, c.countsB.falseAlarms,
                c.countsB.misses);
  }
  std::printf("compare: %zu rows, paired bootstrap over frames, %zu resamples, seed %llu, 95 %%\n", rows.size(),
              o.resamples, static_cast<unsigned long long>(o.seed));
  for (const auto& r : rows)
    std::printf("compare: %s %s %s: F %s %s %s; AP %s %s %s\n", r.className.c_str(), protocolLabel(r).c_str(),
                configLabel(r).c_str(), fixed(r.result.f.difference, true).c_str(), interval(r.result.f.interval).c_str(),
                r.result.f.verdict.c_str(), fixed(r.result.ap.difference, true).c_str(),
                interval(r.result.ap.interval).c_str(), r.result.ap.verdict.c_str());
  return 0;
}

const bool registered = registerCommand(
    "compare",
    "Compare two `fusedet experiments` runs on the same frames: paired bootstrap intervals of F and AP (A - B)",
    [](CLI::App& app) {
      auto o = std::make_shared<CompareOptions>();
      app.add_option("A", o->a,
                     "run A (e.g. with an option): a `fusedet experiments --out` directory (its outcomes.json) or "
                     "an outcomes.json file")
          ->required();
      app.add_option("B", o->b, "run B (e.g. the default), the same")->required();
      app.add_option("--class", o->filter.className, "only this class (car, person, bike); default: every class");
      app.add_option("--protocol", o->filter.protocol,
                     "only this protocol: lodo (leave-one-drive-out, --folds 0) or <k>fold (e.g. 3fold, --folds 3); "
                     "default: every protocol");
      app.add_option("--config", o->filter.config,
                     "only this configuration: all (the joint pool), no_corners, laser, camera, four, and, "
                     "hog; a stage-sweep point all:stages=N,nb=M (--stage-sweep); a learning-curve point "
                     "all:drives=K or all:positives=N|all; default: every configuration");
      app.add_option("--config-b", o->filter.configB,
                     "with --config: B's configuration to pair with A's, when it has another name - e.g. two "
                     "configurations or learning-curve points of one run: `fusedet compare RUN RUN --config "
                     "all:drives=8 --config-b all:drives=4`; the table's config column then reads A_CONFIG/B_CONFIG");
      app.add_option("--protocol-b", o->filter.protocolB,
                     "with --protocol: B's protocol to pair with A's - e.g. the learning curve's point on all "
                     "training frames of 3 folds against the leave-one-drive-out run, the same frames with more "
                     "training data per fold: `fusedet compare LODO 3F --protocol lodo --protocol-b 3fold --config "
                     "all --config-b all:positives=all`; the table's protocol column then reads A/B");
      app.add_option("--bootstrap", o->resamples, "bootstrap resamples of the frames")
          ->check(CLI::Range(1, 1000000))
          ->capture_default_str();
      app.add_option("--seed", o->seed, "bootstrap seed (same seed + files = same intervals)")->capture_default_str();
      app.add_flag("--json", o->json,
                   "print one JSON object instead of the table: a, b (path, command), bootstrap, rows [{class, "
                   "protocol, config, config_b, frames, counts_a, counts_b, f_measure, average_precision}], each measure "
                   "{a, b, difference, interval {lo, hi, resamples} | null, verdict}");
      app.footer(
          "Every `fusedet experiments` run writes OUT/outcomes.json beside results.json: per class, protocol and "
          "configuration (also each stage-sweep and learning-curve point), each test frame's name, positives and counted detections (score, hit or false "
          "alarm) - what F and AP are computed from (format: docs/outcomes-format.md). "
          "compare pairs the (class, protocol, configuration) sets present in both runs and, for each, "
          "resamples the frames with replacement once for both runs (paired bootstrap): the 95 % percentile "
          "interval of F_a - F_b and of AP_a - AP_b. Verdict on \"A is better than B\": holds (interval above "
          "0), contradicted (below 0), not shown (contains 0: a tie). F and AP at full data are what A's and "
          "B's results.json report (same bootstrap settings: same intervals as the run's claims).\n"
          "Refused, exit status 1 with `fusedet compare: error: ...`: different matching rules (e.g. `--min-iou "
          "0.5` against the devkit's 0.7 for car: F under different rules is not comparable), different test "
          "frames, no set in both runs, a missing, truncated or malformed outcomes.json.\n\n"
          "Output: a header line per run (`compare: A PATH: COMMAND`), a table of fixed-width columns, one "
          "line per class / protocol / configuration:\n"
          "  class protocol config frames F_a F_b F_a-F_b [lo, hi] verdict AP_a AP_b AP_a-b [lo, hi] verdict "
          "hits/FA/misses\n"
          "then `compare: N rows, ...` and one `compare: CLASS PROTOCOL CONFIG: F DIFF [lo, hi] VERDICT; AP DIFF "
          "[lo, hi] VERDICT` line per row. Undefined values print as null.\n\n"
          "Examples:\n"
          "  fusedet experiments --classes car --configs all --folds 0 --learning none --no-peers --out def\n"
          "  fusedet experiments --classes car --configs all --folds 0 --learning none --no-peers \\\n"
          "      --laser-extent --out ext\n"
          "  fusedet compare ext def                       # laser extent minus default\n"
          "  fusedet compare ext def --class car --protocol lodo --config all --json | jq '.rows[0].f_measure'\n"
          "  fusedet compare run run --class car --config all:drives=8 --config-b all:drives=4   # more data helps?");
      return [o] { return runCompare(*o); };
    });

}  // namespace
}  // namespace fusedet::tools
