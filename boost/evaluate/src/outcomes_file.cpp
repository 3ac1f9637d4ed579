// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/outcomes_file.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "fusedet/boost/text_position.h"

namespace fusedet::boosting {
namespace {

using Json = nlohmann::ordered_json;
constexpr const char* kFormat = "fusedet-outcomes";
constexpr int kVersion = 1;

Json ruleJson(const MatchConfig& m) {
  return Json{{"min_iou", m.minIou},
              {"min_height", m.minHeight},
              {"max_occlusion", m.maxOcclusion},
              {"max_truncation", m.maxTruncation},
              {"min_detection_height", m.minDetectionHeight},
              {"alias_classes", m.aliasClasses},
              {"neighbour_classes", m.neighbourClasses},
              {"ignore_classes", m.ignoreClasses},
              {"false_alarm_classes", m.falseAlarmClasses}};
}

// Typed access with errors that name the file and the field ("sets[2].frames[7].positives").
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}
  [[noreturn]] void fail(const std::string& where, const std::string& what) const {
    throw OutcomesError(source_ + ": " + (where.empty() ? "" : where + ": ") + what);
  }
  const Json& field(const Json& obj, const std::string& where, const char* key) const {
    const auto it = obj.find(key);
    if (it == obj.end()) fail(where, std::string("missing \"") + key + "\"");
    return *it;
  }
  static std::string at(const std::string& where, const char* key) {
    return where.empty() ? key : where + "." + key;
  }
  const Json& object(const Json& obj, const std::string& where, const char* key) const {
    const Json& v = field(obj, where, key);
    if (!v.is_object()) fail(at(where, key), std::string("expected an object, got ") + v.type_name());
    return v;
  }
  const Json& array(const Json& obj, const std::string& where, const char* key) const {
    const Json& v = field(obj, where, key);
    if (!v.is_array()) fail(at(where, key), std::string("expected an array, got ") + v.type_name());
    return v;
  }
  std::string string(const Json& obj, const std::string& where, const char* key) const {
    const Json& v = field(obj, where, key);
    if (!v.is_string()) fail(at(where, key), std::string("expected a string, got ") + v.type_name());
    return v.get<std::string>();
  }
  double number(const Json& v, const std::string& where) const {
    if (!v.is_number()) fail(where, std::string("expected a number, got ") + v.type_name());
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(where, "not a finite number");
    return d;
  }
  double number(const Json& obj, const std::string& where, const char* key) const {
    return number(field(obj, where, key), at(where, key));
  }
  std::size_t count(const Json& v, const std::string& where, std::size_t max) const {
    if (!v.is_number_unsigned()) fail(where, std::string("expected a count (integer >= 0), got ") + v.dump());
    const auto n = v.get<std::uint64_t>();
    if (n > max) fail(where, std::to_string(n) + " is out of range (at most " + std::to_string(max) + ")");
    return static_cast<std::size_t>(n);
  }
  std::size_t count(const Json& obj, const std::string& where, const char* key, std::size_t max) const {
    return count(field(obj, where, key), at(where, key), max);
  }
  std::vector<std::string> strings(const Json& obj, const std::string& where, const char* key) const {
    const Json& v = array(obj, where, key);
    std::vector<std::string> out;
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_string()) fail(at(where, key) + "[" + std::to_string(i) + "]", "expected a string");
      out.push_back(v[i].get<std::string>());
    }
    return out;
  }

 private:
  std::string source_;
};

MatchConfig ruleFromJson(const Reader& r, const Json& j, const std::string& where, const std::string& cls) {
  MatchConfig m;
  m.className = cls;
  m.minIou = r.number(j, where, "min_iou");
  if (m.minIou <= 0 || m.minIou > 1) r.fail(where + ".min_iou", "must lie in (0, 1]");
  m.minHeight = r.number(j, where, "min_height");
  m.maxOcclusion = static_cast<int>(r.count(j, where, "max_occlusion", 1000));
  m.maxTruncation = r.number(j, where, "max_truncation");
  m.minDetectionHeight = r.number(j, where, "min_detection_height");
  m.aliasClasses = r.strings(j, where, "alias_classes");
  m.neighbourClasses = r.strings(j, where, "neighbour_classes");
  m.ignoreClasses = r.strings(j, where, "ignore_classes");
  m.falseAlarmClasses = r.strings(j, where, "false_alarm_classes");
  return m;
}

// A frame: {"id": "kitti/000000", "positives": 2, "detections": [[score, 1 = hit | 0 = false alarm], ...]}.
void frameFromJson(const Reader& r, const Json& j, const std::string& where, OutcomeSet& set) {
  if (!j.is_object()) r.fail(where, std::string("expected an object, got ") + j.type_name());
  const std::string id = r.string(j, where, "id");
  if (id.empty()) r.fail(where + ".id", "empty frame name");
  FrameOutcome f;
  f.positives = r.count(j, where, "positives", 1u << 20);
  const Json& dets = r.array(j, where, "detections");
  std::size_t hits = 0;
  for (std::size_t i = 0; i < dets.size(); ++i) {
    const std::string w = where + ".detections[" + std::to_string(i) + "]";
    if (!dets[i].is_array() || dets[i].size() != 2) r.fail(w, "expected [score, hit (1) or false alarm (0)]");
    FrameOutcome::Scored s;
    s.score = r.number(dets[i][0], w + "[0]");
    const std::size_t hit = r.count(dets[i][1], w + "[1]", 1);
    s.hit = hit == 1;
    hits += hit;
    f.detections.push_back(s);
  }
  if (hits > f.positives)
    r.fail(where, std::to_string(hits) + " hits but only " + std::to_string(f.positives) +
                      " positives (each positive is hit at most once)");
  set.frameIds.push_back(id);
  set.frames.push_back(std::move(f));
}

}  // namespace

std::string protocolName(std::size_t folds, std::size_t groups) {
  return folds == groups ? "lodo" : std::to_string(folds) + "fold";
}

std::string outcomesToText(const RunOutcomes& run) {
  std::ostringstream o;
  o << "{\"format\": \"" << kFormat << "\", \"version\": " << kVersion << ", \"command\": " << Json(run.command).dump()
    << ",\n \"sets\": [";
  for (std::size_t s = 0; s < run.sets.size(); ++s) {
    const OutcomeSet& set = run.sets[s];
    if (set.frameIds.size() != set.frames.size())
      throw std::invalid_argument("outcomes of " + set.className + "/" + set.config + ": " +
                                  std::to_string(set.frameIds.size()) + " frame ids for " +
                                  std::to_string(set.frames.size()) + " frames");
    o << (s ? "," : "") << "\n  {\"class\": " << Json(set.className).dump() << ", \"protocol\": "
      << Json(set.protocol).dump() << ", \"folds\": " << set.folds << ", \"config\": " << Json(set.config).dump()
      << ",\n   \"rule\": " << ruleJson(set.rule).dump() << ",\n   \"frames\": [";
    for (std::size_t i = 0; i < set.frames.size(); ++i) {
      Json dets = Json::array();
      for (const auto& d : set.frames[i].detections) dets.push_back(Json::array({d.score, d.hit ? 1 : 0}));
      o << (i ? "," : "") << "\n    {\"id\": " << Json(set.frameIds[i]).dump()
        << ", \"positives\": " << set.frames[i].positives << ", \"detections\": " << dets.dump() << "}";
    }
    o << "]}";
  }
  o << "]}\n";
  return o.str();
}

RunOutcomes outcomesFromText(const std::string& text, const std::string& source) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw OutcomesError(source + ": " + lineColumn(text, e.byte > 0 ? e.byte - 1 : 0) + ": not valid JSON (" +
                        e.what() + ")");
  } catch (const Json::exception& e) {  // e.g. a number too large for a double
    throw OutcomesError(source + ": not a valid outcomes file (" + e.what() + ")");
  }
  const Reader r(source);
  if (!root.is_object()) r.fail("", std::string("expected a JSON object, got ") + root.type_name());
  const std::string format = r.string(root, "", "format");
  if (format != kFormat) r.fail("format", "'" + format + "' is not a fusedet outcomes file");
  const std::size_t version = r.count(root, "", "version", 1u << 20);
  if (version != kVersion)
    r.fail("version", "unsupported version " + std::to_string(version) + " (this build reads " +
                          std::to_string(kVersion) + ")");
  RunOutcomes run;
  run.command = r.string(root, "", "command");
  const Json& sets = r.array(root, "", "sets");
  std::set<std::string> keys;
  for (std::size_t s = 0; s < sets.size(); ++s) {
    const std::string where = "sets[" + std::to_string(s) + "]";
    const Json& j = sets[s];
    if (!j.is_object()) r.fail(where, std::string("expected an object, got ") + j.type_name());
    OutcomeSet set;
    set.className = r.string(j, where, "class");
    set.protocol = r.string(j, where, "protocol");
    set.folds = r.count(j, where, "folds", 1u << 20);
    set.config = r.string(j, where, "config");
    if (set.className.empty() || set.protocol.empty() || set.config.empty())
      r.fail(where, "class, protocol and config must not be empty");
    if (!keys.insert(set.className + "/" + set.protocol + "/" + set.config).second)
      r.fail(where, set.className + " / " + set.protocol + " / " + set.config + " appears twice");
    set.rule = ruleFromJson(r, r.object(j, where, "rule"), where + ".rule", set.className);
    const Json& frames = r.array(j, where, "frames");
    std::set<std::string> ids;
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const std::string w = where + ".frames[" + std::to_string(i) + "]";
      frameFromJson(r, frames[i], w, set);
      if (!ids.insert(set.frameIds.back()).second) r.fail(w, "frame '" + set.frameIds.back() + "' appears twice");
    }
    run.sets.push_back(std::move(set));
  }
  return run;
}

void writeOutcomes(const std::filesystem::path& file, const RunOutcomes& run) {
  const std::string text = outcomesToText(run);
  std::ofstream out(file, std::ios::binary);
  out << text;
  out.flush();
  if (!out) throw OutcomesError(file.string() + ": cannot write");
}

RunOutcomes readOutcomes(const std::filesystem::path& path) {
  const std::filesystem::path file = std::filesystem::is_directory(path) ? path / "outcomes.json" : path;
  std::ifstream in(file, std::ios::binary);
  if (!in)
    throw OutcomesError(file.string() + ": cannot open (" +
                        (std::filesystem::exists(file) ? "not readable" : "no such file; a `fusedet experiments` "
                                                                          "run writes it beside results.json") +
                        ")");
  std::ostringstream s;
  s << in.rdbuf();
  return outcomesFromText(s.str(), file.string());
}

}  // namespace fusedet::boosting
