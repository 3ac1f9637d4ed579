// SPDX-License-Identifier: Apache-2.0
#include "data.h"

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <fstream>
#include <map>
#include <sstream>
#include <stdexcept>

#include "fusedet/fusion/datasets/kitti_drives.h"
#include "fusedet/fusion/datasets/kitti_import.h"
#include "fusedet/fusion/datasets/kitti_tracks.h"
#include "fusedet/fusion/layer_sources.h"

namespace fusedet::tools::experiments {
std::vector<fs::path> kittiDrives(const fs::path& root) {
  const auto isDrive = [](const fs::path& p) {
    return fs::is_directory(p / "image_2") && fs::is_directory(p / "label_2") &&
           fs::is_directory(p / "velodyne") && fs::is_directory(p / "calib");
  };
  if (isDrive(root)) return {root};
  std::vector<fs::path> drives;
  for (const char* known : {"kitti", "kitti_0009", "kitti_object_sample"})
    if (isDrive(root / known)) drives.push_back(root / known);
  std::vector<fs::path> others;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(root, ec))
    if (e.is_directory() && isDrive(e.path()) &&
        std::find(drives.begin(), drives.end(), e.path()) == drives.end())
      others.push_back(e.path());
  std::sort(others.begin(), others.end());
  drives.insert(drives.end(), others.begin(), others.end());
  return drives;
}

fs::path resolveDataset(const ExperimentOptions& o) {
  if (fs::exists(o.data / "dataset.json")) {
    std::printf("data set: %s\n", o.data.c_str());
    return o.data;
  }
  const std::vector<fs::path> drives = kittiDrives(o.data);
  if (drives.empty())
    throw std::runtime_error(o.data.string() +
                             ": neither a data set (no dataset.json) nor a directory of KITTI drives "
                             "(image_2/, label_2/, velodyne/, calib/)");
  const fs::path cache = o.datasetCache.empty() ? o.out / "dataset" : o.datasetCache;
  std::string signature;
  for (const auto& d : drives) signature += fs::absolute(d).lexically_normal().string() + "\n";
  fusion::KittiImportOptions import;
  import.neural = o.network.load();
  if (import.neural) {
    signature += "network " + import.neural->identity().text() + "\n";
    std::printf("network %s\n", import.neural->identity().text().c_str());
  }
  const fs::path marker = cache / "imported-from.txt";
  if (std::ifstream in(marker); in) {
    std::stringstream s;
    s << in.rdbuf();
    if (s.str() == signature) {
      std::printf("data set: %s (imported earlier from %zu KITTI drives)\n", cache.c_str(), drives.size());
      return cache;
    }
  }
  fs::remove_all(cache);
  for (const fs::path& d : drives) {
    const std::string group = d.filename().string();
    const auto stats = fusion::importKitti(d, group, cache, import);
    std::printf("imported %s -> group %s: %zu frames, %zu labels (%zu ignore regions)\n", d.c_str(),
                group.c_str(), stats.frames, stats.labels, stats.ignoreRegions);
  }
  std::ofstream(marker) << signature;
  return cache;
}

std::vector<std::string> drivesOf(const ExperimentOptions& o, const std::vector<DatasetEntry>& manifest) {
  std::map<std::string, fusion::KittiDriveMap> maps;
  if (!fs::exists(o.data / "dataset.json"))
    for (const fs::path& d : kittiDrives(o.data)) maps[d.filename().string()] = fusion::readKittiDriveMap(d);
  std::vector<std::string> drives;
  for (const DatasetEntry& e : manifest) {
    const auto it = maps.find(e.group);
    const std::string frame = e.id.substr(e.id.find('/') + 1);
    drives.push_back(it == maps.end() ? e.group : it->second.driveOf(frame, e.group));
  }
  return drives;
}

std::vector<std::vector<std::string>> objectIdsOf(const ExperimentOptions& o, const std::vector<DatasetEntry>& manifest,
                                                  const std::vector<Labels>& labels,
                                                  const std::vector<std::string>& driveOf) {
  std::map<std::string, fusion::KittiTracks> tracks;
  if (!fs::exists(o.data / "dataset.json"))
    for (const fs::path& d : kittiDrives(o.data)) tracks[d.filename().string()] = fusion::readKittiTracks(d);
  std::vector<std::vector<std::string>> out(manifest.size());
  for (std::size_t i = 0; i < manifest.size(); ++i) {
    const auto it = tracks.find(manifest[i].group);
    if (it == tracks.end() || it->second.frames.empty()) continue;
    const std::string frame = manifest[i].id.substr(manifest[i].id.find('/') + 1);
    int number = -1;
    const auto [end, ec] = std::from_chars(frame.data(), frame.data() + frame.size(), number);
    if (ec == std::errc() && end == frame.data() + frame.size())
      out[i] = it->second.objectIds(driveOf[i], number, labels[i]);
  }
  return out;
}

std::vector<DatasetItem> loadItems(const fs::path& dataset, const std::vector<DatasetEntry>& entries,
                                   const std::vector<std::string>& driveOf, bool withNetwork) {
  std::vector<std::string> layers = {"red", "green", "blue", "intensity", "hue", "distance", "remission"};
  if (withNetwork)
    for (const std::string& l : fusion::networkPoolLayers()) layers.push_back(l);
  std::vector<DatasetItem> items;
  items.reserve(entries.size());
  for (std::size_t i = 0; i < entries.size(); ++i) {
    items.push_back(readDatasetItem(dataset, entries[i].id, layers));
    items.back().group = driveOf[i];
  }
  return items;
}

}  // namespace fusedet::tools::experiments
