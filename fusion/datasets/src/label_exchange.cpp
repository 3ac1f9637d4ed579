// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/label_exchange.h"

#include <algorithm>
#include <cctype>
#include <map>
#include <stdexcept>

#include "fusedet/core/dataset.h"

namespace fusedet::fusion {
namespace fs = std::filesystem;

namespace {

std::string lower(std::string s) {
  std::transform(s.begin(), s.end(), s.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return s;
}

}  // namespace

std::optional<std::string> LabelClassTable::lookup(const std::string& name) const {
  const std::string key = lower(name);
  for (const auto& [external, project] : entries)
    if (lower(external) == key) return project;
  return std::nullopt;
}

void LabelClassTable::set(const std::string& spec) {
  const auto eq = spec.find('=');
  if (eq == std::string::npos || eq == 0)
    throw std::invalid_argument("--map '" + spec +
                                "': expected NAME=CLASS, e.g. Pedestrian=person or Truck=ignore");
  const std::string name = spec.substr(0, eq);
  std::string project = spec.substr(eq + 1);
  if (project == "ignore") project.clear();
  // Later entries of the same name win: drop the old one so lookup finds the new.
  std::erase_if(entries, [&](const auto& e) { return lower(e.first) == lower(name); });
  entries.emplace_back(name, project);
}

Label exchangeLabel(const LabelClassTable& table, const std::string& name, const std::string& where) {
  const auto project = table.lookup(name);
  if (!project)
    throw std::runtime_error(where + ": class '" + name + "' is not in the class table; map it with --map '" +
                             name + "=CLASS' (or '" + name + "=ignore' for an ignore region)");
  Label l;
  l.sourceClass = name;
  l.ignore = project->empty();
  l.className = l.ignore ? name : *project;
  return l;
}

std::string imageNameOf(const std::string& itemId) {
  return itemId + ".png";
}

std::string itemIdOf(const std::string& imageName) {
  std::string id = imageName;
  if (id.starts_with("./")) id.erase(0, 2);
  const auto slash = id.rfind('/');
  const auto dot = id.rfind('.');
  if (dot != std::string::npos && (slash == std::string::npos || dot > slash) && dot > 0) id.erase(dot);
  return id;
}

std::vector<ExchangeImage> exchangeImages(const fs::path& datasetDir) {
  std::vector<ExchangeImage> images;
  for (const std::string& id : listDataset(datasetDir)) {
    DatasetItem item = readDatasetItemLabels(datasetDir, id);
    images.push_back(
        ExchangeImage{imageNameOf(id), item.stack.width(), item.stack.height(), std::move(item.labels)});
  }
  return images;
}

ApplyLabelsResult applyExchangeImages(const fs::path& datasetDir, const std::vector<ExchangeImage>& images,
                                      bool allowUnmatched) {
  return applyExchangeImages(datasetDir, exchangeImages(datasetDir), images, allowUnmatched);
}

ApplyLabelsResult applyExchangeImages(const fs::path& datasetDir, const std::vector<ExchangeImage>& current,
                                      const std::vector<ExchangeImage>& images, bool allowUnmatched) {
  std::map<std::string, const ExchangeImage*> items;  // item id -> its labels and reference size
  for (const ExchangeImage& item : current) items.emplace(itemIdOf(item.name), &item);
  std::multimap<std::string, std::string> byLastSegment;
  for (const auto& [id, item] : items) byLastSegment.emplace(id.substr(id.rfind('/') + 1), id);

  ApplyLabelsResult result;
  std::vector<std::pair<std::string, const ExchangeImage*>> matched;
  for (const ExchangeImage& image : images) {
    std::string id = itemIdOf(image.name);
    if (!items.count(id)) {
      const auto [first, last] = byLastSegment.equal_range(id);
      if (id.find('/') == std::string::npos && first != last && std::next(first) == last) {
        id = first->second;
      } else {
        if (first != last && std::next(first) != last)
          throw std::runtime_error("image '" + image.name + "' matches several items (" + first->second +
                                   ", " + std::next(first)->second +
                                   ", ...): name it by its item id, e.g. '" + imageNameOf(first->second) +
                                   "'");
        if (!allowUnmatched)
          throw std::runtime_error("image '" + image.name + "' is no item of " + datasetDir.string() +
                                   " (item '" + id + "' not found; images are named <item id>.png)");
        result.unmatched.push_back(image.name);
        continue;
      }
    }
    matched.emplace_back(id, &image);
  }
  // Check every size before writing anything, so a wrong file changes no item.
  for (const auto& [id, image] : matched) {
    if (image->width == 0 && image->height == 0) continue;
    const ExchangeImage& item = *items.at(id);
    if (image->width != item.width || image->height != item.height)
      throw std::runtime_error("image '" + image->name + "' is " + std::to_string(image->width) + "x" +
                               std::to_string(image->height) + " but item '" + id + "' is " +
                               std::to_string(item.width) + "x" + std::to_string(item.height));
  }
  for (const auto& [id, image] : matched) {
    writeDatasetItemLabels(datasetDir, id, image->labels);
    ++result.items;
    result.labels += image->labels.size();
  }
  return result;
}

}  // namespace fusedet::fusion
