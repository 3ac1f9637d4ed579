// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/paired_comparison.h"

#include <map>
#include <sstream>
#include <string>

namespace fusedet::boosting {
namespace {

using Measure = std::optional<double> (*)(const std::vector<FrameOutcome>&, const std::vector<std::size_t>&);

std::optional<double> fOf(const std::vector<FrameOutcome>& f, const std::vector<std::size_t>& idx) {
  return fMeasureOf(f, idx);
}
std::optional<double> apOf(const std::vector<FrameOutcome>& f, const std::vector<std::size_t>& idx) {
  return averagePrecisionOf(f, idx);
}

PairedMeasure paired(const std::vector<FrameOutcome>& a, const std::vector<FrameOutcome>& b, Measure m,
                     const BootstrapConfig& boot) {
  const auto diff = [&](const std::vector<std::size_t>& idx) -> std::optional<double> {
    const auto x = m(a, idx), y = m(b, idx);
    if (!x || !y) return std::nullopt;
    return *x - *y;
  };
  std::vector<std::size_t> all(a.size());
  for (std::size_t i = 0; i < all.size(); ++i) all[i] = i;
  PairedMeasure p;
  p.a = m(a, all);
  p.b = m(b, all);
  p.difference = diff(all);
  p.interval = bootstrapInterval(a.size(), diff, boot);
  p.verdict = verdict(p.interval);
  return p;
}

std::string key(const OutcomeSet& s) { return s.className + " / " + s.protocol + " / " + s.config; }

// The shortest text that reads back as v, so that rules that differ print differently.
std::string num(double v) {
  std::string s;
  for (int digits = 6; digits <= 17; ++digits) {
    std::ostringstream o;
    o.precision(digits);
    o << v;
    s = o.str();
    if (std::stod(s) == v) break;
  }
  return s;
}
std::string list(const std::vector<std::string>& v) {
  std::string s = "[";
  for (const auto& x : v) s += (s.size() > 1 ? ", " : "") + x;
  return s + "]";
}

// What differs between two matching rules, "" when nothing.
std::string ruleDifference(const MatchConfig& a, const MatchConfig& b) {
  std::string d;
  const auto add = [&](const char* name, bool differs, const std::string& x, const std::string& y) {
    if (differs) d += (d.empty() ? "" : ", ") + std::string(name) + " " + x + " against " + y;
  };
  const auto addNumber = [&](const char* name, double x, double y) { add(name, x != y, num(x), num(y)); };
  const auto addList = [&](const char* name, const std::vector<std::string>& x, const std::vector<std::string>& y) {
    add(name, x != y, list(x), list(y));
  };
  addNumber("hit overlap (IoU)", a.minIou, b.minIou);
  addNumber("min label height", a.minHeight, b.minHeight);
  addNumber("max occlusion", a.maxOcclusion, b.maxOcclusion);
  addNumber("max truncation", a.maxTruncation, b.maxTruncation);
  addNumber("min detection height", a.minDetectionHeight, b.minDetectionHeight);
  addList("alias classes", a.aliasClasses, b.aliasClasses);
  addList("neighbour classes", a.neighbourClasses, b.neighbourClasses);
  addList("ignore classes", a.ignoreClasses, b.ignoreClasses);
  addList("false-alarm classes", a.falseAlarmClasses, b.falseAlarmClasses);
  return d;
}

}  // namespace

PairedComparison comparePaired(const std::vector<FrameOutcome>& a, const std::vector<FrameOutcome>& b,
                               const BootstrapConfig& boot) {
  if (a.size() != b.size())
    throw std::invalid_argument("paired comparison: " + std::to_string(a.size()) + " against " +
                                std::to_string(b.size()) + " frames");
  PairedComparison c;
  c.frames = a.size();
  c.countsA = countsOf(allFrames(a));
  c.countsB = countsOf(allFrames(b));
  c.f = paired(a, b, fOf, boot);
  c.ap = paired(a, b, apOf, boot);
  return c;
}

PairedComparison compareSets(const OutcomeSet& a, const OutcomeSet& b, const BootstrapConfig& boot) {
  const std::string what = key(a) + " against " + key(b);
  if (a.className != b.className) throw ComparisonError(what + ": different classes");
  if (const std::string d = ruleDifference(a.rule, b.rule); !d.empty())
    throw ComparisonError(what + ": the runs match detections by different rules (" + d +
                          "); F and AP under different rules are not comparable");
  std::map<std::string, std::size_t> indexOfB;
  for (std::size_t i = 0; i < b.frameIds.size(); ++i) indexOfB[b.frameIds[i]] = i;
  std::vector<std::string> onlyA, onlyB;
  std::vector<FrameOutcome> alignedB;
  for (const std::string& id : a.frameIds) {
    const auto it = indexOfB.find(id);
    if (it == indexOfB.end()) {
      onlyA.push_back(id);
    } else {
      alignedB.push_back(b.frames.at(it->second));
      indexOfB.erase(it);
    }
  }
  for (const auto& [id, i] : indexOfB) onlyB.push_back(id);
  if (!onlyA.empty() || !onlyB.empty()) {
    const auto some = [](const std::vector<std::string>& v) {
      std::string s;
      for (std::size_t i = 0; i < v.size() && i < 3; ++i) s += (i ? ", " : "") + v[i];
      return s + (v.size() > 3 ? ", ..." : "");
    };
    std::string d = what + ": the runs tested different frames (" + std::to_string(a.frameIds.size()) + " against " +
                    std::to_string(b.frameIds.size());
    if (!onlyA.empty()) d += "; " + std::to_string(onlyA.size()) + " only in the first: " + some(onlyA);
    if (!onlyB.empty()) d += "; " + std::to_string(onlyB.size()) + " only in the second: " + some(onlyB);
    throw ComparisonError(d + ")");
  }
  return comparePaired(a.frames, alignedB, boot);
}

std::vector<ComparisonRow> compareRuns(const RunOutcomes& a, const RunOutcomes& b, const ComparisonFilter& filter,
                                       const BootstrapConfig& boot) {
  const auto passes = [&](const OutcomeSet& s) {
    return (filter.className.empty() || s.className == filter.className) &&
           (filter.protocol.empty() || s.protocol == filter.protocol) &&
           (filter.config.empty() || s.config == filter.config);
  };
  if (!filter.configB.empty() && filter.config.empty())
    throw std::invalid_argument("a configuration of the second run (" + filter.configB +
                                ") needs the first run's configuration to pair it with");
  if (!filter.protocolB.empty() && filter.protocol.empty())
    throw std::invalid_argument("a protocol of the second run (" + filter.protocolB +
                                ") needs the first run's protocol to pair it with");
  std::vector<ComparisonRow> rows;
  for (const OutcomeSet& x : a.sets) {
    if (!passes(x)) continue;
    const std::string other = filter.configB.empty() ? x.config : filter.configB;
    const std::string otherProtocol = filter.protocolB.empty() ? x.protocol : filter.protocolB;
    for (const OutcomeSet& y : b.sets)
      if (y.className == x.className && y.protocol == otherProtocol && y.config == other)
        rows.push_back({x.className, x.protocol, x.config, other, otherProtocol, compareSets(x, y, boot)});
  }
  if (rows.empty()) {
    const auto has = [&](const RunOutcomes& r) {
      std::string s;
      for (const OutcomeSet& x : r.sets) s += (s.empty() ? "" : ", ") + key(x);
      return s.empty() ? std::string("nothing") : s;
    };
    std::string f;
    if (!filter.className.empty()) f += " class " + filter.className;
    if (!filter.protocol.empty()) f += " protocol " + filter.protocol;
    if (!filter.config.empty()) f += " config " + filter.config;
    if (!filter.configB.empty()) f += " against config " + filter.configB;
    if (!filter.protocolB.empty()) f += " against protocol " + filter.protocolB;
    throw ComparisonError("no class / protocol / configuration" + (f.empty() ? "" : " matching" + f) +
                          " is in both runs (first: " + has(a) + "; second: " + has(b) + ")");
  }
  return rows;
}

}  // namespace fusedet::boosting
