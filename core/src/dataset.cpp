// SPDX-License-Identifier: Apache-2.0
#include "fusedet/core/dataset.h"

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <set>

#include "dataset_codec.h"

namespace fusedet {
namespace fs = std::filesystem;
using nlohmann::json;
using namespace dataset_detail;

namespace {
constexpr int kVersion = 1;
constexpr const char* kManifest = "dataset.json";
constexpr const char* kItemFile = "item.json";
constexpr int kMaxSide = 1 << 16;  // no sensor layer is larger; guards against absurd allocations

[[noreturn]] void fail(const fs::path& file, const std::string& what) {
  throw DatasetError(file.string() + ": " + what);
}

bool isNameChar(char c) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         c == '-';
}

// Ids become paths: '/'-separated segments (isIdSegment), nothing absolute.
bool validId(const std::string& id) {
  if (id.empty() || id.size() > 200 || id.front() == '/' || id.back() == '/') return false;
  std::size_t start = 0;
  while (start <= id.size()) {
    std::size_t end = id.find('/', start);
    if (end == std::string::npos) end = id.size();
    if (!isIdSegment(id.substr(start, end - start))) return false;
    start = end + 1;
  }
  return true;
}

// Layer names become file names; no '.' so "<name>.valid.png" can never be another layer's file.
bool validLayerName(const std::string& name) {
  return !name.empty() && name.size() <= 64 && std::all_of(name.begin(), name.end(), isNameChar);
}

// Typed access to a JSON object member; every problem names the file and the key path.
const json& member(const fs::path& file, const json& obj, const std::string& key, const std::string& where) {
  if (!obj.is_object()) fail(file, where + " is not a JSON object");
  const auto it = obj.find(key);
  if (it == obj.end()) fail(file, where + " has no \"" + key + "\"");
  return *it;
}
std::string getString(const fs::path& file, const json& obj, const std::string& key, const std::string& where) {
  const json& v = member(file, obj, key, where);
  if (!v.is_string()) fail(file, where + "." + key + " must be a string");
  return v.get<std::string>();
}
double getNumber(const fs::path& file, const json& obj, const std::string& key, const std::string& where) {
  const json& v = member(file, obj, key, where);
  if (!v.is_number()) fail(file, where + "." + key + " must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(file, where + "." + key + " must be finite");
  return d;
}
std::int64_t getInt(const fs::path& file, const json& obj, const std::string& key, const std::string& where,
                    std::int64_t lo, std::int64_t hi) {
  const json& v = member(file, obj, key, where);
  if (!v.is_number_integer()) fail(file, where + "." + key + " must be an integer");
  const bool huge = v.is_number_unsigned() && v.get<std::uint64_t>() > static_cast<std::uint64_t>(INT64_MAX);
  const std::int64_t i = huge ? INT64_MAX : v.get<std::int64_t>();
  if (huge || i < lo || i > hi)
    fail(file, where + "." + key + " = " + v.dump() + " is outside [" + std::to_string(lo) + ", " +
                   std::to_string(hi) + "]");
  return i;
}
bool getBool(const fs::path& file, const json& obj, const std::string& key, const std::string& where) {
  const json& v = member(file, obj, key, where);
  if (!v.is_boolean()) fail(file, where + "." + key + " must be true or false");
  return v.get<bool>();
}

json parseJsonFile(const fs::path& file) {
  const std::vector<unsigned char> bytes = readBytes(file);
  json j = json::parse(bytes.begin(), bytes.end(), nullptr, /*allow_exceptions=*/false);
  if (j.is_discarded()) fail(file, "not valid JSON (corrupt or truncated)");
  return j;
}

void checkHeader(const fs::path& file, const json& j, const std::string& format) {
  if (getString(file, j, "format", "top level") != format)
    fail(file, "\"format\" is not \"" + format + "\"");
  const auto version = getInt(file, j, "version", "top level", 0, INT32_MAX);
  if (version != kVersion)
    fail(file, "version " + std::to_string(version) + " not supported (this build reads " +
                   std::to_string(kVersion) + ")");
}

fs::path itemDir(const fs::path& datasetDir, const std::string& id) { return datasetDir / "items" / id; }

json labelToJson(const Label& l) {
  return json{{"class", l.className}, {"source_class", l.sourceClass}, {"x", l.box.x}, {"y", l.box.y},
              {"w", l.box.w},         {"h", l.box.h},                  {"truncation", l.truncation},
              {"occlusion", l.occlusion}, {"ignore", l.ignore},                {"origin", l.origin}};
}

Label labelFromJson(const fs::path& file, const json& j, const std::string& where) {
  Label l;
  l.className = getString(file, j, "class", where);
  l.sourceClass = getString(file, j, "source_class", where);
  l.box = Box{getNumber(file, j, "x", where), getNumber(file, j, "y", where), getNumber(file, j, "w", where),
              getNumber(file, j, "h", where)};
  if (l.box.w < 0 || l.box.h < 0) fail(file, where + " has a negative width or height");
  l.truncation = getNumber(file, j, "truncation", where);
  l.occlusion = static_cast<int>(getInt(file, j, "occlusion", where, -1, 3));
  l.ignore = getBool(file, j, "ignore", where);
  // Optional: data sets written before labels had an origin were labelled by people.
  if (j.contains("origin")) {
    l.origin = getString(file, j, "origin", where);
    if (l.origin != "human" && l.origin != "teacher") fail(file, where + ".origin must be \"human\" or \"teacher\"");
  }
  return l;
}

void writeManifest(const fs::path& datasetDir, const std::vector<DatasetEntry>& entries) {
  json items = json::array();
  for (const DatasetEntry& e : entries) items.push_back(json{{"id", e.id}, {"group", e.group}});
  const std::string text =
      json{{"format", "fusedet-dataset"}, {"version", kVersion}, {"items", items}}.dump(1) + "\n";
  writeBytesAtomic(datasetDir / kManifest, text.data(), text.size());
}

// The item.json of `id`, parsed and with its header checked.
json readItemJson(const fs::path& datasetDir, const std::string& id, fs::path& file) {
  if (!validId(id)) throw DatasetError(datasetDir.string() + ": invalid item id '" + id + "'");
  file = itemDir(datasetDir, id) / kItemFile;
  json j = parseJsonFile(file);
  checkHeader(file, j, "fusedet-item");
  if (getString(file, j, "id", "top level") != id) fail(file, "\"id\" does not match the item's directory '" + id + "'");
  return j;
}

// Everything of an item but its layers.
DatasetItem itemFromJson(const fs::path& file, const json& j) {
  DatasetItem item;
  item.id = getString(file, j, "id", "top level");
  item.group = getString(file, j, "group", "top level");
  const int w = static_cast<int>(getInt(file, j, "width", "top level", 1, kMaxSide));
  const int h = static_cast<int>(getInt(file, j, "height", "top level", 1, kMaxSide));
  item.stack.setReferenceSize(w, h);
  item.stack.stamp = Stamp{getInt(file, j, "stamp_ns", "top level", INT64_MIN, INT64_MAX)};
  item.stack.id = static_cast<std::uint64_t>(getInt(file, j, "stack_id", "top level", 0, INT64_MAX));
  item.stack.source = getString(file, j, "source", "top level");
  if (j.contains("network")) {
    try {
      item.stack.network = parseNetworkRecord(getString(file, j, "network", "top level"));
    } catch (const std::invalid_argument& e) {
      fail(file, e.what());
    }
  }
  const json& labels = member(file, j, "labels", "top level");
  if (!labels.is_array()) fail(file, "\"labels\" must be an array");
  for (std::size_t i = 0; i < labels.size(); ++i)
    item.labels.push_back(labelFromJson(file, labels[i], "labels[" + std::to_string(i) + "]"));
  return item;
}

}  // namespace

bool isIdSegment(const std::string& segment) {
  return !segment.empty() && segment != "." && segment != ".." &&
         std::all_of(segment.begin(), segment.end(), [](char c) { return isNameChar(c) || c == '.'; });
}

std::string toIdSegment(std::string name, const std::string& fallback) {
  for (char& c : name)
    if (!isNameChar(c) && c != '.') c = '_';
  return isIdSegment(name) ? name : fallback;
}

std::vector<DatasetEntry> readDatasetManifest(const fs::path& datasetDir) {
  const fs::path file = datasetDir / kManifest;
  const json j = parseJsonFile(file);
  checkHeader(file, j, "fusedet-dataset");
  const json& items = member(file, j, "items", "top level");
  if (!items.is_array()) fail(file, "\"items\" must be an array");
  std::vector<DatasetEntry> out;
  std::set<std::string> seen;
  for (std::size_t i = 0; i < items.size(); ++i) {
    const std::string where = "items[" + std::to_string(i) + "]";
    DatasetEntry e{getString(file, items[i], "id", where), getString(file, items[i], "group", where)};
    if (!validId(e.id)) fail(file, where + ": invalid id '" + e.id + "'");
    if (!seen.insert(e.id).second) fail(file, where + ": duplicate id '" + e.id + "'");
    out.push_back(std::move(e));
  }
  return out;
}

std::vector<std::string> listDataset(const fs::path& datasetDir) {
  std::vector<std::string> ids;
  for (DatasetEntry& e : readDatasetManifest(datasetDir)) ids.push_back(std::move(e.id));
  return ids;
}

void writeDatasetItem(const fs::path& datasetDir, const DatasetItem& item) {
  if (!validId(item.id))
    throw DatasetError(datasetDir.string() + ": invalid item id '" + item.id +
                       "' ('/'-separated segments of letters, digits, '_', '-', '.')");
  if (item.group.empty()) throw DatasetError(datasetDir.string() + ": item '" + item.id + "' has no group");
  const LayerStack& s = item.stack;
  if (s.width() <= 0 || s.height() <= 0 || s.width() > kMaxSide || s.height() > kMaxSide)
    throw DatasetError(datasetDir.string() + ": item '" + item.id + "' has no valid reference size");

  const fs::path dir = itemDir(datasetDir, item.id);
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) fail(dir, "cannot create: " + ec.message());

  json layers = json::array();
  std::set<std::string> files{kItemFile};
  for (const Layer& l : s.layers()) {
    const std::string what = (dir / kItemFile).string() + ": layer '" + l.name + "'";
    if (!validLayerName(l.name)) throw DatasetError(what + ": name must be letters, digits, '_' or '-'");
    if (l.data.empty()) throw DatasetError(what + ": empty");
    const Quantised q = quantise(l.data, l.name, what);
    const std::string png = l.name + ".png";
    writePng(dir / png, q.stored);
    files.insert(png);
    json entry{{"name", l.name},       {"file", png},         {"type", typeName(l.data.depth())},
               {"width", l.width()},   {"height", l.height()}, {"scale", q.scale},
               {"offset", q.offset},   {"mask", nullptr}};
    if (l.hasMask()) {
      const std::string mask = l.name + ".valid.png";
      writePng(dir / mask, l.valid);
      files.insert(mask);
      entry["mask"] = mask;
    }
    layers.push_back(std::move(entry));
  }
  json labels = json::array();
  for (const Label& l : item.labels) labels.push_back(labelToJson(l));
  json j{{"format", "fusedet-item"}, {"version", kVersion}, {"id", item.id},
               {"group", item.group},      {"source", s.source},  {"stack_id", s.id},
               {"stamp_ns", s.stamp.ns},   {"width", s.width()},  {"height", s.height()},
               {"labels", labels},         {"layers", layers}};
  if (!s.network.empty()) j["network"] = s.network.text();
  const std::string text = j.dump(1) + "\n";
  writeBytesAtomic(dir / kItemFile, text.data(), text.size());
  // A replaced item may have had more layers: drop files the new item.json does not name.
  for (const auto& entry : fs::directory_iterator(dir, ec))
    if (entry.is_regular_file() && !files.contains(entry.path().filename().string()) &&
        entry.path().extension() == ".png")
      fs::remove(entry.path(), ec);

  std::vector<DatasetEntry> entries;
  if (fs::exists(datasetDir / kManifest)) entries = readDatasetManifest(datasetDir);
  auto it = std::find_if(entries.begin(), entries.end(), [&](const DatasetEntry& e) { return e.id == item.id; });
  if (it != entries.end())
    it->group = item.group;
  else
    entries.push_back(DatasetEntry{item.id, item.group});
  writeManifest(datasetDir, entries);
}

DatasetItem readDatasetItemLabels(const fs::path& datasetDir, const std::string& id) {
  fs::path file;
  const json j = readItemJson(datasetDir, id, file);
  return itemFromJson(file, j);
}

void writeDatasetItemLabels(const fs::path& datasetDir, const std::string& id, const Labels& labels) {
  fs::path file;
  json j = readItemJson(datasetDir, id, file);
  itemFromJson(file, j);  // the rest of the item must be valid before it is rewritten
  json out = json::array();
  for (const Label& l : labels) {
    if (!std::isfinite(l.box.x) || !std::isfinite(l.box.y) || !std::isfinite(l.box.w) || !std::isfinite(l.box.h))
      fail(file, "label of class '" + l.className + "' has a box that is not finite");
    out.push_back(labelToJson(l));
  }
  j["labels"] = std::move(out);
  const std::string text = j.dump(1) + "\n";
  writeBytesAtomic(file, text.data(), text.size());
}

DatasetItem readDatasetItem(const fs::path& datasetDir, const std::string& id,
                            const std::vector<std::string>& wanted) {
  fs::path file;
  const json j = readItemJson(datasetDir, id, file);
  DatasetItem item = itemFromJson(file, j);
  const fs::path dir = file.parent_path();
  const json& layers = member(file, j, "layers", "top level");
  if (!layers.is_array()) fail(file, "\"layers\" must be an array");
  std::set<std::string> found;
  for (std::size_t i = 0; i < layers.size(); ++i) {
    const std::string where = "layers[" + std::to_string(i) + "]";
    const json& e = layers[i];
    Layer l;
    l.name = getString(file, e, "name", where);
    if (!validLayerName(l.name)) fail(file, where + ": invalid layer name '" + l.name + "'");
    if (found.contains(l.name)) fail(file, where + ": duplicate layer '" + l.name + "'");
    found.insert(l.name);
    if (!wanted.empty() && std::find(wanted.begin(), wanted.end(), l.name) == wanted.end()) continue;
    const std::string type = getString(file, e, "type", where);
    const int depth = depthOfType(type);
    if (depth < 0) fail(file, where + ".type '" + type + "' is not u8, u16 or f32");
    const int w = static_cast<int>(getInt(file, e, "width", where, 1, kMaxSide));
    const int h = static_cast<int>(getInt(file, e, "height", where, 1, kMaxSide));
    const double scale = getNumber(file, e, "scale", where), offset = getNumber(file, e, "offset", where);
    if (depth == CV_32F && !(scale > 0)) fail(file, where + ".scale must be > 0");
    if (depth != CV_32F && (scale != 1 || offset != 0)) fail(file, where + ": " + type + " layers need scale 1, offset 0");
    const std::string png = getString(file, e, "file", where);
    if (png != l.name + ".png") fail(file, where + ".file must be \"" + l.name + ".png\"");
    l.data = dequantise(readPng(dir / png, depth, w, h), depth, scale, offset);
    const json& mask = member(file, e, "mask", where);
    if (mask.is_string()) {
      if (mask.get<std::string>() != l.name + ".valid.png") fail(file, where + ".mask must be \"" + l.name + ".valid.png\" or null");
      l.valid = readPng(dir / mask.get<std::string>(), CV_8U, w, h);
    } else if (!mask.is_null()) {
      fail(file, where + ".mask must be a file name or null");
    }
    item.stack.set(std::move(l));
  }
  for (const std::string& name : wanted)
    if (!found.contains(name)) fail(file, "has no layer '" + name + "'");
  // Keep the caller's order when layers were selected, so stacks of one data set line up.
  if (!wanted.empty()) {
    LayerStack ordered(item.stack.width(), item.stack.height());
    ordered.id = item.stack.id;
    ordered.stamp = item.stack.stamp;
    ordered.source = item.stack.source;
    ordered.network = item.stack.network;
    for (const std::string& name : wanted)
      if (Layer* l = item.stack.find(name); l && !ordered.has(name)) ordered.set(std::move(*l));
    item.stack = std::move(ordered);
  }
  return item;
}

}  // namespace fusedet
