// SPDX-License-Identifier: Apache-2.0
#include "fusedet/fusion/datasets/kitti_label_files.h"

#include <algorithm>
#include <cstdio>
#include <fstream>
#include <stdexcept>

#include "fusedet/fusion/datasets/kitti.h"

namespace fusedet::fusion {
namespace fs = std::filesystem;

std::string kittiClassName(const Label& label) {
  static const std::vector<std::pair<std::string, std::string>> kNames = {
      {"person", "Pedestrian"}, {"car", "Car"}, {"bike", "Cyclist"}, {"van", "Van"}};
  static const std::vector<std::string> kKitti = {"Car",     "Van",  "Truck", "Pedestrian", "Person_sitting",
                                                  "Cyclist", "Tram", "Misc",  "DontCare"};
  if (label.ignore)
    return std::find(kKitti.begin(), kKitti.end(), label.className) != kKitti.end() ? label.className
                                                                                    : "DontCare";
  for (const auto& [project, kitti] : kNames)
    if (label.className == project) return kitti;
  return label.className;
}

std::size_t writeKittiLabelFiles(const fs::path& dir, const std::vector<ExchangeImage>& images) {
  std::size_t files = 0;
  for (const ExchangeImage& image : images) {
    const fs::path file = dir / (itemIdOf(image.name) + ".txt");
    std::error_code ec;
    fs::create_directories(file.parent_path(), ec);
    if (ec) throw std::runtime_error(file.parent_path().string() + ": cannot create: " + ec.message());
    std::ofstream out(file);
    if (!out) throw std::runtime_error(file.string() + ": cannot write");
    for (const Label& l : image.labels) {
      char line[256];
      std::snprintf(line, sizeof line, "%s %.2f %d -10 %.2f %.2f %.2f %.2f -1 -1 -1 -1000 -1000 -1000 -10\n",
                    kittiClassName(l).c_str(), l.truncation, l.occlusion, l.box.x, l.box.y, l.box.x + l.box.w,
                    l.box.y + l.box.h);
      out << line;
    }
    if (!out.flush()) throw std::runtime_error(file.string() + ": write failed");
    ++files;
  }
  return files;
}

std::vector<ExchangeImage> readKittiLabelFiles(const fs::path& dir, const LabelClassTable& table) {
  if (!fs::is_directory(dir))
    throw std::runtime_error(dir.string() + ": not a directory of KITTI label files");
  std::vector<fs::path> files;
  for (const auto& entry : fs::recursive_directory_iterator(dir))
    if (entry.is_regular_file() && entry.path().extension() == ".txt") files.push_back(entry.path());
  std::sort(files.begin(), files.end());
  std::vector<ExchangeImage> images;
  for (const fs::path& file : files) {
    // The KITTI parser with an empty class map keeps every type as it is; the table maps it here.
    Labels labels = readKittiLabels(file, KittiClassMap{{}});
    for (Label& l : labels) {
      Label mapped = exchangeLabel(table, l.sourceClass, file.string());
      mapped.box = l.box;
      mapped.truncation = l.truncation;
      mapped.occlusion = l.occlusion;
      l = std::move(mapped);
    }
    const std::string relative = fs::relative(file, dir).replace_extension().generic_string();
    images.push_back(ExchangeImage{imageNameOf(relative), 0, 0, std::move(labels)});
  }
  return images;
}

}  // namespace fusedet::fusion
