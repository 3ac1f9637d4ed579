// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/coco_labels.h"

#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <utility>

namespace fusedet::fusion {
using nlohmann::json;

namespace {

// COCO 2017's ids of the classes we share with it; other names get ids from 1000 up.
const std::map<std::string, int> kCocoIds = {{"person", 1}, {"bicycle", 2}, {"car", 3}, {"truck", 8}};

[[noreturn]] void fail(const std::string& file, const std::string& what) {
  throw std::runtime_error(file + ": " + what);
}

const json& field(const std::string& file, const json& obj, const char* key, const std::string& where) {
  if (!obj.is_object()) fail(file, where + " is not an object");
  const auto it = obj.find(key);
  if (it == obj.end()) fail(file, where + " has no \"" + key + "\"");
  return *it;
}

std::int64_t integer(const std::string& file, const json& obj, const char* key, const std::string& where) {
  const json& v = field(file, obj, key, where);
  if (!v.is_number_integer()) fail(file, where + "." + key + " must be an integer");
  return v.get<std::int64_t>();
}

double finite(const std::string& file, const json& v, const std::string& where) {
  if (!v.is_number()) fail(file, where + " must be a number");
  const double d = v.get<double>();
  if (!std::isfinite(d)) fail(file, where + " must be finite");
  return d;
}

const json& array(const std::string& file, const json& coco, const char* key) {
  const json& v = field(file, coco, key, "top level");
  if (!v.is_array()) fail(file, std::string("\"") + key + "\" must be an array");
  return v;
}

}  // namespace

std::string cocoClassName(const std::string& projectClass) {
  return projectClass == "bike" ? "bicycle" : projectClass;
}

json cocoResults(const std::vector<std::string>& manifestIds,
                 const std::vector<std::pair<std::string, std::vector<Detection>>>& detectionsPerItem) {
  std::map<std::string, int> imageIds;
  for (std::size_t i = 0; i < manifestIds.size(); ++i) imageIds.emplace(manifestIds[i], static_cast<int>(i) + 1);
  json results = json::array();
  for (const auto& [item, detections] : detectionsPerItem) {
    const auto image = imageIds.find(item);
    if (image == imageIds.end()) throw std::invalid_argument("COCO results: item '" + item + "' is not in the data set");
    for (const Detection& d : detections) {
      const auto category = kCocoIds.find(cocoClassName(d.className));
      if (category == kCocoIds.end())
        throw std::invalid_argument("COCO results: class '" + d.className + "' has no COCO category");
      results.push_back({{"image_id", image->second},
                         {"category_id", category->second},
                         {"bbox", {d.box.x, d.box.y, d.box.w, d.box.h}},
                         {"score", d.score}});
    }
  }
  return results;
}

json cocoFromImages(const std::vector<ExchangeImage>& images) {
  std::map<std::string, int> categoryIds;
  int nextId = 1000;
  auto categoryOf = [&](const Label& l) {
    const std::string name = l.ignore ? l.className : cocoClassName(l.className);
    auto [it, added] = categoryIds.emplace(name, 0);
    if (added) it->second = kCocoIds.contains(name) ? kCocoIds.at(name) : nextId++;
    return it->second;
  };
  json jsonImages = json::array(), annotations = json::array();
  int annotationId = 1;
  for (std::size_t i = 0; i < images.size(); ++i) {
    const ExchangeImage& image = images[i];
    const int imageId = static_cast<int>(i) + 1;
    jsonImages.push_back(
        {{"id", imageId}, {"file_name", image.name}, {"width", image.width}, {"height", image.height}});
    for (const Label& l : image.labels)
      annotations.push_back({{"id", annotationId++},
                             {"image_id", imageId},
                             {"category_id", categoryOf(l)},
                             {"bbox", {l.box.x, l.box.y, l.box.w, l.box.h}},
                             {"area", l.box.w * l.box.h},
                             {"iscrowd", l.ignore ? 1 : 0},
                             {"occlusion", l.occlusion},
                             {"truncation", l.truncation},
                             {"origin", l.origin}});
  }
  json categories = json::array();
  for (const auto& [name, id] : categoryIds)
    categories.push_back({{"id", id}, {"name", name}, {"supercategory", name}});
  return {{"info", {{"description", "fusedet data set labels"}, {"version", "1.0"}}},
          {"licenses", json::array()},
          {"images", jsonImages},
          {"annotations", annotations},
          {"categories", categories}};
}

std::vector<ExchangeImage> imagesFromCoco(const json& coco, const LabelClassTable& table,
                                          const std::string& file) {
  if (!coco.is_object()) fail(file, "not a COCO file (the top level is not an object)");
  std::map<std::int64_t, std::string> categories;
  const json& jsonCategories = array(file, coco, "categories");
  for (std::size_t i = 0; i < jsonCategories.size(); ++i) {
    const std::string where = "categories[" + std::to_string(i) + "]";
    const std::int64_t id = integer(file, jsonCategories[i], "id", where);
    const json& name = field(file, jsonCategories[i], "name", where);
    if (!name.is_string()) fail(file, where + ".name must be a string");
    if (!categories.emplace(id, name.get<std::string>()).second)
      fail(file, where + ": category id " + std::to_string(id) + " twice");
  }
  std::vector<ExchangeImage> images;
  std::map<std::int64_t, std::size_t> imageIndex;
  std::set<std::string> names;
  const json& jsonImages = array(file, coco, "images");
  for (std::size_t i = 0; i < jsonImages.size(); ++i) {
    const std::string where = "images[" + std::to_string(i) + "]";
    const std::int64_t id = integer(file, jsonImages[i], "id", where);
    const json& name = field(file, jsonImages[i], "file_name", where);
    if (!name.is_string() || name.get<std::string>().empty())
      fail(file, where + ".file_name must be a non-empty string");
    const std::int64_t w = integer(file, jsonImages[i], "width", where),
                       h = integer(file, jsonImages[i], "height", where);
    if (w <= 0 || h <= 0 || w > (1 << 16) || h > (1 << 16))
      fail(file, where + ": width and height must be 1..65536");
    if (!imageIndex.emplace(id, images.size()).second)
      fail(file, where + ": image id " + std::to_string(id) + " twice");
    if (!names.insert(name.get<std::string>()).second)
      fail(file, where + ": file_name '" + name.get<std::string>() + "' twice");
    images.push_back(ExchangeImage{name.get<std::string>(), static_cast<int>(w), static_cast<int>(h), {}});
  }
  std::set<std::int64_t> annotationIds;
  const json& annotations = array(file, coco, "annotations");
  for (std::size_t i = 0; i < annotations.size(); ++i) {
    const std::string where = "annotations[" + std::to_string(i) + "]";
    const json& a = annotations[i];
    if (!annotationIds.insert(integer(file, a, "id", where)).second)
      fail(file, where + ": annotation id twice");
    const auto image = imageIndex.find(integer(file, a, "image_id", where));
    if (image == imageIndex.end()) fail(file, where + ".image_id names no image");
    const auto category = categories.find(integer(file, a, "category_id", where));
    if (category == categories.end()) fail(file, where + ".category_id names no category");
    const json& bbox = field(file, a, "bbox", where);
    if (!bbox.is_array() || bbox.size() != 4) fail(file, where + ".bbox must be [x, y, width, height]");
    Label l = exchangeLabel(table, category->second, file + ": " + where);
    l.box = Box{finite(file, bbox[0], where + ".bbox[0]"), finite(file, bbox[1], where + ".bbox[1]"),
                finite(file, bbox[2], where + ".bbox[2]"), finite(file, bbox[3], where + ".bbox[3]")};
    if (l.box.w < 0 || l.box.h < 0) fail(file, where + ".bbox has a negative width or height");
    if (a.contains("iscrowd")) {
      const json& crowd = a["iscrowd"];
      if (!crowd.is_number_integer() || (crowd.get<int>() != 0 && crowd.get<int>() != 1))
        fail(file, where + ".iscrowd must be 0 or 1");
      if (crowd.get<int>() == 1) {
        l.ignore = true;
        const auto project = table.lookup(category->second);
        l.className = project && !project->empty() ? *project : category->second;
      }
    }
    if (a.contains("occlusion")) {
      const double o = finite(file, a["occlusion"], where + ".occlusion");
      if (o != std::floor(o) || o < -1 || o > 3) fail(file, where + ".occlusion must be an integer -1..3");
      l.occlusion = static_cast<int>(o);
    }
    if (a.contains("truncation")) l.truncation = finite(file, a["truncation"], where + ".truncation");
    if (a.contains("origin")) {
      if (a["origin"] != "human" && a["origin"] != "teacher") fail(file, where + ".origin must be \"human\" or \"teacher\"");
      l.origin = a["origin"].get<std::string>();
    }
    images[image->second].labels.push_back(std::move(l));
  }
  return images;
}

}  // namespace fusedet::fusion
