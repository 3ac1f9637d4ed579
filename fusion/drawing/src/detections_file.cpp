// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/drawing/detections_file.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <stdexcept>

namespace fusedet::fusion {
namespace {
[[noreturn]] void fail(const std::string& what, const std::string& problem) {
  throw std::runtime_error(what + ": " + problem);
}
double number(const nlohmann::json& d, const char* key, const std::string& what, const std::string& where) {
  const auto it = d.find(key);
  if (it == d.end() || !it->is_number()) fail(what, where + "." + key + " must be a number");
  const double v = it->get<double>();
  if (!std::isfinite(v)) fail(what, where + "." + key + " must be finite");
  return v;
}
}  // namespace

std::vector<Detection> parseDetectionsJson(const std::string& text, const std::string& what) {
  const nlohmann::json j = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) fail(what, "not valid JSON");
  if (!j.is_object() || !j.contains("detections") || !j["detections"].is_array())
    fail(what, "expected an object with a \"detections\" array");
  std::vector<Detection> out;
  const auto& list = j["detections"];
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = "detections[" + std::to_string(i) + "]";
    const auto& d = list[i];
    if (!d.is_object()) fail(what, where + " is not an object");
    Detection det;
    const auto cls = d.find("class");
    if (cls == d.end() || !cls->is_string()) fail(what, where + ".class must be a string");
    det.className = cls->get<std::string>();
    det.score = number(d, "score", what, where);
    det.box = Box{number(d, "x", what, where), number(d, "y", what, where), number(d, "w", what, where),
                  number(d, "h", what, where)};
    if (det.box.w < 0 || det.box.h < 0) fail(what, where + " has a negative width or height");
    out.push_back(std::move(det));
  }
  return out;
}

std::vector<Detection> readDetectionsFile(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) fail(file.string(), "cannot open detections file");
  std::stringstream text;
  text << in.rdbuf();
  return parseDetectionsJson(text.str(), file.string());
}

}  // namespace fusedet::fusion
