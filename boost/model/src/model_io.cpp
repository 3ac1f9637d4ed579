// SPDX-License-Identifier: Apache-2.0
#include "fusedet/boost/model_io.h"

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>

#include "fusedet/boost/text_position.h"

namespace fusedet::boosting {

namespace {

using Json = nlohmann::ordered_json;

// Reads fields of a parsed model with the JSON path of every value, for messages.
class Reader {
 public:
  explicit Reader(std::string source) : source_(std::move(source)) {}

  [[noreturn]] void fail(const std::string& place, const std::string& reason) const {
    throw ModelError(source_ + ": " + (place.empty() ? std::string("top level") : place) + ": " + reason);
  }
  static std::string typeName(const Json& j) { return j.type_name(); }

  const Json& field(const Json& obj, const std::string& place, const char* key) const {
    if (!obj.is_object()) fail(place, std::string("expected an object, got ") + typeName(obj));
    const auto it = obj.find(key);
    if (it == obj.end()) fail(join(place, key), "missing");
    return *it;
  }
  double number(const Json& obj, const std::string& place, const char* key) const {
    const Json& v = field(obj, place, key);
    if (!v.is_number()) fail(join(place, key), "expected a number, got " + typeName(v));
    const double d = v.get<double>();
    if (!std::isfinite(d)) fail(join(place, key), "not a finite number");
    return d;
  }
  int integer(const Json& obj, const std::string& place, const char* key, int lo, int hi) const {
    const Json& v = field(obj, place, key);
    if (!v.is_number_integer()) fail(join(place, key), "expected an integer, got " + typeName(v));
    const auto i = v.get<long long>();
    if (i < lo || i > hi)
      fail(join(place, key), std::to_string(i) + " out of range [" + std::to_string(lo) + ", " +
                                 std::to_string(hi) + "]");
    return static_cast<int>(i);
  }
  std::string string(const Json& obj, const std::string& place, const char* key) const {
    const Json& v = field(obj, place, key);
    if (!v.is_string()) fail(join(place, key), "expected a string, got " + typeName(v));
    return v.get<std::string>();
  }
  const Json& array(const Json& obj, const std::string& place, const char* key) const {
    const Json& v = field(obj, place, key);
    if (!v.is_array()) fail(join(place, key), "expected an array, got " + typeName(v));
    return v;
  }
  static std::string join(const std::string& place, const char* key) {
    return place.empty() ? std::string(key) : place + "." + key;
  }
  static std::string at(const std::string& place, std::size_t i) {
    return place + "[" + std::to_string(i) + "]";
  }

 private:
  std::string source_;
};

// Format versions written only for options that were removed (they measured no gain across
// drives, issue 29): their files are refused, never read as a model they are not.
struct RemovedVersion {
  int version;
  const char* option;
};
constexpr RemovedVersion kRemovedVersions[] = {
    {2, "contrast normalisation"},
    {3, "soft cascade"},
    {4, "side-view (aspect) cascades"},
    {5, "tree weak learners"},
};

}  // namespace

std::string modelToText(const Cascade& c, const ModelInfo& info) {
  if (c.isOpenCv())
    throw ModelError(c.source + ": an imported OpenCV cascade cannot be written as a fusedet model");
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw ModelError(std::string("cannot write an invalid cascade: ") + e.what());
  }
  std::ostringstream o;
  o << "{\n";
  o << "  \"format\": " << Json(kModelFormatName).dump() << ",\n";
  o << "  \"version\": " << kModelFormatVersion << ",\n";
  o << "  \"class\": " << Json(c.className).dump() << ",\n";
  o << "  \"window\": " << Json{{"width", c.windowWidth}, {"height", c.windowHeight}}.dump() << ",\n";
  o << "  \"layers\": " << Json(c.layers).dump() << ",\n";
  o << "  \"reference_hue\": " << (c.referenceHue ? Json(*c.referenceHue) : Json(nullptr)).dump() << ",\n";
  if (!c.network.empty()) o << "  \"network\": " << Json(c.network.text()).dump() << ",\n";
  if (!info.empty()) {
    Json t = Json::object();
    for (const auto& [k, v] : info) t[k] = v;
    o << "  \"training\": " << t.dump() << ",\n";
  }
  o << "  \"stages\": [\n";
  for (std::size_t s = 0; s < c.stages.size(); ++s) {
    const Stage& st = c.stages[s];
    o << "    {\"threshold\":" << Json(st.threshold).dump() << ",\"stumps\":[\n";
    for (std::size_t k = 0; k < st.stumps.size(); ++k) {
      const Stump& sp = st.stumps[k];
      const Feature& f = c.features.at(static_cast<std::size_t>(sp.feature));
      Json j;
      j["type"] = std::string(1, toLetter(f.type));
      j["rect"] = {f.rect.x, f.rect.y, f.rect.w, f.rect.h};
      j["layer"] = c.layers.at(static_cast<std::size_t>(f.layer));
      j["threshold"] = sp.threshold;
      j["left"] = sp.left;
      j["right"] = sp.right;
      o << "      " << j.dump() << (k + 1 < st.stumps.size() ? ",\n" : "\n");
    }
    o << "    ]}" << (s + 1 < c.stages.size() ? ",\n" : "\n");
  }
  o << "  ]\n}\n";
  return o.str();
}

Cascade modelFromText(const std::string& text, const std::string& source) {
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::parse_error& e) {
    throw ModelError(source + ": " + lineColumn(text, e.byte > 0 ? e.byte - 1 : 0) +
                     ": not valid JSON (" + e.what() + ")");
  } catch (const Json::exception& e) {  // e.g. a number too large for a double
    throw ModelError(source + ": not a valid model (" + e.what() + ")");
  }
  const Reader r(source);
  if (!root.is_object()) r.fail("", std::string("expected a JSON object, got ") + root.type_name());
  const std::string format = r.string(root, "", "format");
  if (format != kModelFormatName) r.fail("format", "'" + format + "' is not a fusedet cascade model");
  const int version = r.integer(root, "", "version", 1, 1 << 20);
  for (const RemovedVersion& removed : kRemovedVersions)
    if (version == removed.version)
      r.fail("version", "model format version " + std::to_string(version) + " (" + removed.option +
                            ") was removed in fusedet 0.1.0 (the option measured no gain across "
                            "drives); retrain the model with `fusedet train`");
  if (version != kModelFormatVersion)
    r.fail("version", "unsupported version " + std::to_string(version) + " (this build reads " +
                          std::to_string(kModelFormatVersion) + ")");
  Cascade c;
  c.source = source;
  c.className = r.string(root, "", "class");
  const Json& window = r.field(root, "", "window");
  c.windowWidth = r.integer(window, "window", "width", 1, 1 << 16);
  c.windowHeight = r.integer(window, "window", "height", 1, 1 << 16);
  const Json& layers = r.array(root, "", "layers");
  if (layers.empty()) r.fail("layers", "no layers");
  for (std::size_t i = 0; i < layers.size(); ++i) {
    if (!layers[i].is_string()) r.fail(Reader::at("layers", i), "expected a string");
    const std::string name = layers[i].get<std::string>();
    for (const auto& l : c.layers)
      if (l == name) r.fail(Reader::at("layers", i), "layer '" + name + "' listed twice");
    c.layers.push_back(name);
  }
  const Json& hue = r.field(root, "", "reference_hue");
  if (!hue.is_null()) c.referenceHue = r.number(root, "", "reference_hue");
  if (root.contains("network")) {
    try {
      c.network = parseNetworkRecord(r.string(root, "", "network"));
    } catch (const std::invalid_argument& e) {
      r.fail("network", e.what());
    }
  }
  // Written by --min-height-from-positives, removed (a tie cross-drive): such a model would now scan
  // from its base window, so it is refused rather than run differently without a word.
  if (root.contains("min_height"))
    r.fail("min_height", "a model's own minimum detection height (train --min-height-from-positives) is no longer "
                         "supported; retrain the model with `fusedet train`, or delete the field to scan from the "
                         "base window");
  const Json& stages = r.array(root, "", "stages");
  if (stages.empty()) r.fail("stages", "no stages");
  std::vector<std::pair<Feature, int>> seen;  // features in first-use order (shared by stumps)
  for (std::size_t s = 0; s < stages.size(); ++s) {
    const std::string sp = Reader::at("stages", s);
    Stage st;
    st.threshold = r.number(stages[s], sp, "threshold");
    const Json& stumps = r.array(stages[s], sp, "stumps");
    if (stumps.empty()) r.fail(Reader::join(sp, "stumps"), "empty stage");
    for (std::size_t k = 0; k < stumps.size(); ++k) {
      const std::string kp = Reader::at(Reader::join(sp, "stumps"), k);
      const Json& j = stumps[k];
      Feature f;
      const std::string type = r.string(j, kp, "type");
      const auto t = type.size() == 1 ? featureTypeFromLetter(type[0]) : std::nullopt;
      if (!t) r.fail(Reader::join(kp, "type"), "unknown feature type '" + type + "' (expected a-j)");
      f.type = *t;
      const Json& rect = r.array(j, kp, "rect");
      if (rect.size() != 4) r.fail(Reader::join(kp, "rect"), "expected [x, y, w, h]");
      double v[4];
      for (std::size_t q = 0; q < 4; ++q) {
        if (!rect[q].is_number() || !std::isfinite(rect[q].get<double>()))
          r.fail(Reader::at(Reader::join(kp, "rect"), q), "expected a finite number");
        v[q] = rect[q].get<double>();
      }
      f.rect = Box{v[0], v[1], v[2], v[3]};
      const std::string layer = r.string(j, kp, "layer");
      const auto li = std::find(c.layers.begin(), c.layers.end(), layer);
      if (li == c.layers.end()) r.fail(Reader::join(kp, "layer"), "layer '" + layer + "' is not in \"layers\"");
      f.layer = static_cast<int>(li - c.layers.begin());
      try {
        validateFeature(f, c.layers.size());
      } catch (const std::invalid_argument& e) {
        r.fail(kp, e.what());
      }
      Stump stump;
      stump.threshold = r.number(j, kp, "threshold");
      stump.left = r.number(j, kp, "left");
      stump.right = r.number(j, kp, "right");
      int index = -1;
      for (const auto& [g, i] : seen)
        if (g == f) index = i;
      if (index < 0) {
        index = c.addFeature(f);
        seen.emplace_back(f, index);
      }
      stump.feature = index;
      st.stumps.push_back(stump);
    }
    c.stages.push_back(std::move(st));
  }
  try {
    c.validate();
  } catch (const std::invalid_argument& e) {
    throw ModelError(e.what());  // Cascade::validate names c.source already
  }
  return c;
}

void saveModel(const Cascade& cascade, const std::filesystem::path& file, const ModelInfo& info) {
  const std::string text = modelToText(cascade, info);
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  if (!out) throw ModelError(file.string() + ": cannot open for writing");
  out << text;
  out.flush();
  if (!out) throw ModelError(file.string() + ": write failed");
}

namespace {
std::string readModelText(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  if (!in) throw ModelError(file.string() + ": cannot open (" +
                            (std::filesystem::exists(file) ? "not readable" : "no such file") + ")");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}
}  // namespace

Cascade loadModel(const std::filesystem::path& file) { return modelFromText(readModelText(file), file.string()); }

ModelInfo loadModelInfo(const std::filesystem::path& file) {
  const std::string text = readModelText(file);
  Json root;
  try {
    root = Json::parse(text);
  } catch (const Json::exception& e) {
    throw ModelError(file.string() + ": not valid JSON (" + e.what() + ")");
  }
  ModelInfo info;
  if (!root.is_object() || !root.contains("training") || !root["training"].is_object()) return info;
  for (const auto& [k, v] : root["training"].items()) info.emplace_back(k, v.is_string() ? v.get<std::string>() : v.dump());
  return info;
}

}  // namespace fusedet::boosting
